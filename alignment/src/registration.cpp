// Acquisition by PCL: point-to-plane ICP (damped, holding weak directions), the quality gate, the footing,
// and FPFH + SampleConsensusPrerejective; its filters, normals and features are pcl_steps.cpp's.

#include "projbot/alignment/registration.hpp"

#include <pcl/console/print.h>
#include <pcl/filters/voxel_grid.h>
#include <pcl/kdtree/kdtree_flann.h>
#include <pcl/registration/correspondence_rejection_median_distance.h>
#include <pcl/registration/correspondence_rejection_surface_normal.h>
#include <pcl/registration/icp.h>
#include <pcl/registration/sample_consensus_prerejective.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>
#include <optional>
#include <utility>
#include <vector>

#include "pcl_steps.hpp"
#include "projbot/alignment/equations.hpp"
#include "projbot/alignment/verification.hpp"
#include "projbot/config/angles.hpp"
#include "projbot/config/clock.hpp"
#include "projbot/config/stop_request.hpp"
#include "serial_kdtree.hpp"

namespace projbot::alignment {
namespace {

using namespace detail;  // PCL's filters, normals and features (pcl_steps.hpp)

// How far (in inlier tolerances) beside the model's outline its own surface can lie outside an estimate
// the gate should catch: farther, an unexplained point is a neighbour's. (Without it, the wood block the
// YCB-V banana leans on counted against the right pose: inlier ratio 0.66 at the truth, 0.96 with it.)
constexpr float kBesideReach = 2.0F;

// PCL keeps the iteration count protected; the result struct reports it.
class CountingIcp : public pcl::IterativeClosestPointWithNormals<PointN, PointN> {
 public:
  explicit CountingIcp(bool point_to_plane, bool hold_weak = false) {
    min_number_correspondences_ = 10;
    if (point_to_plane)
      setTransformationEstimation(damped_ = pcl::make_shared<DampedPointToPlane>(hold_weak));
    else
      setTransformationEstimation(pcl::make_shared<pcl::registration::TransformationEstimationSVD<PointN, PointN>>());
  }
  int iterations() const { return nr_iterations_; }
  /// Weak directions its newest step held (hold_weak), else 0.
  int held() const { return damped_ ? damped_->held() : 0; }

 private:
  std::shared_ptr<DampedPointToPlane> damped_;
};

}  // namespace

struct Aligner::Impl {
  AcquisitionConfig cfg;
  CloudN::Ptr model;                     // all model samples, model frame: for the quality metrics
  CloudN::Ptr model_icp;                 // voxel-downsampled: ICP source
  CloudN::Ptr model_coarse;              // coarser: re-initialisation
  mutable Features::Ptr model_features;  // computed on the first re-initialisation, then kept
  mutable int feature_computations = 0;
  pcl::search::KdTree<PointN>::Ptr model_tree;
  pcl::search::KdTree<PointN>::Ptr model_icp_tree;
  Extent extent;

  double coarse_leaf() const { return std::max(cfg.voxel_m * 2.0, 0.008); }

  // Finite scan points within `crop_radius` of `centre` (all of them when crop_radius <= 0), downsampled,
  // outliers removed. Empty when fewer than min_points remain.
  pcl::PointCloud<pcl::PointXYZ>::Ptr prepare(const PointCloud& scan, const Eigen::Vector3f& centre, double crop_radius,
                                              double leaf) const {
    auto raw = pcl::make_shared<pcl::PointCloud<pcl::PointXYZ>>();
    const float r2 = static_cast<float>(crop_radius * crop_radius);
    for (const auto& p : scan.points)
      if (p.allFinite() && (crop_radius <= 0.0 || (p - centre).squaredNorm() <= r2))
        raw->push_back(pcl::PointXYZ(p.x(), p.y(), p.z()));
    return filter(raw, leaf);
  }

  // Finite scan points inside the model's bounding box, grown by `margin`, under T_scan_model: unlike
  // a sphere, the box leaves out most of what the target stands on (a pedestal, the floor).
  pcl::PointCloud<pcl::PointXYZ>::Ptr prepare_in_box(const PointCloud& scan, const Eigen::Matrix4d& T_scan_model, double margin,
                                                     double leaf) const {
    const Eigen::Matrix4f T_model_scan = rigid_inverse(T_scan_model).cast<float>();
    const Eigen::Matrix3f R = T_model_scan.topLeftCorner<3, 3>();
    const Eigen::Vector3f t = T_model_scan.topRightCorner<3, 1>();
    const Eigen::Vector3f lo = extent.box.min().array() - static_cast<float>(margin);
    const Eigen::Vector3f hi = extent.box.max().array() + static_cast<float>(margin);
    auto raw = pcl::make_shared<pcl::PointCloud<pcl::PointXYZ>>();
    for (const auto& p : scan.points) {
      if (!p.allFinite()) continue;
      const Eigen::Vector3f q = R * p + t;
      if ((q.array() >= lo.array()).all() && (q.array() <= hi.array()).all()) raw->push_back(pcl::PointXYZ(p.x(), p.y(), p.z()));
    }
    return filter(raw, leaf);
  }

  pcl::PointCloud<pcl::PointXYZ>::Ptr filter(const pcl::PointCloud<pcl::PointXYZ>::Ptr& raw, double leaf) const {
    if (raw->size() < cfg.min_points) return pcl::make_shared<pcl::PointCloud<pcl::PointXYZ>>();
    auto down = pcl::make_shared<pcl::PointCloud<pcl::PointXYZ>>();
    pcl::VoxelGrid<pcl::PointXYZ> grid;
    grid.setInputCloud(raw);
    grid.setLeafSize(static_cast<float>(leaf), static_cast<float>(leaf), static_cast<float>(leaf));
    grid.filter(*down);
    // A surface's points fall with the square of the leaf, a noisy one's more slowly: up to three
    // coarser grids bring them within a quarter over the cap.
    for (int i = 0; i < 3 && cfg.max_scan_points > 0 && down->size() > cfg.max_scan_points * 5 / 4; ++i) {
      leaf *= std::sqrt(static_cast<double>(down->size()) / static_cast<double>(cfg.max_scan_points));
      grid.setLeafSize(static_cast<float>(leaf), static_cast<float>(leaf), static_cast<float>(leaf));
      grid.filter(*down);
    }
    if (down->size() > static_cast<std::size_t>(cfg.outlier_neighbours) * 2) {
      down = cfg.pcl_search ? pcl_outliers_removed(down, cfg.outlier_neighbours, cfg.outlier_stddev)
                            : outliers_removed(down, cfg.outlier_neighbours, cfg.outlier_stddev);
    }
    if (down->size() < cfg.min_points) down->clear();
    return down;
  }

  // The scan prepared around where the model sits under T_scan_model, its box grown by `margin`: what
  // an ICP stage and the gate work on. Without cropping, all of it.
  pcl::PointCloud<pcl::PointXYZ>::Ptr near_scan(const PointCloud& scan, const Eigen::Matrix4d& T_scan_model, double margin,
                                                double leaf = 0.0) const {
    if (leaf <= 0.0) leaf = cfg.voxel_m;
    if (!cfg.crop) return prepare(scan, Eigen::Vector3f::Zero(), 0.0, leaf);
    return prepare_in_box(scan, T_scan_model, margin, leaf);
  }
  // What the quality gate judges: the box grown by a little more than the inlier distance.
  double gate_margin() const { return 3.0 * cfg.inlier_distance_m; }

  // Point-to-plane ICP, coarse then fine correspondence distance. The scan is the source: every scan
  // point has a true match on the complete model, while the model's unseen side has none in the scan and
  // would pull the estimate. The planes are the model's exact surface normals, and the model's search
  // tree is built once, in the constructor.
  // Each stage crops the scan afresh around the current estimate: the first with the whole crop margin
  // (the initial guess may be that far off), later ones with their correspondence distance, so that
  // what the target stands on drops out as the estimate tightens.
  // Out of time (a bounded attempt's deadline, checked between stages): not converged.
  Eigen::Matrix4d icp(const PointCloud& scan, const Eigen::Matrix4d& T_scan_model_init, int& iterations, bool& converged,
                      const std::function<bool()>& out_of_time, std::size_t first_stage = 0, bool hold_weak = false,
                      int* held = nullptr) const {
    Eigen::Matrix4f T_model_scan = rigid_inverse(T_scan_model_init).cast<float>();
    converged = true;
    for (std::size_t stage = first_stage; stage < cfg.icp_distances_m.size(); ++stage) {
      if (stage > first_stage && out_of_time()) {
        converged = false;
        break;
      }
      const double distance = cfg.icp_distances_m[stage];
      // Coarse stages need fewer points: a leaf of a tenth of the correspondence distance, at least voxel_m.
      const auto near = near_scan(scan, rigid_inverse(T_model_scan.cast<double>()), stage == 0 ? cfg.crop_margin_m : distance,
                                  std::max(cfg.voxel_m, distance / 10.0));
      if (near->size() < cfg.min_points) {
        converged = false;
        break;
      }
      // Scan normals (towards the sensor) let correspondences whose surfaces disagree be rejected: the
      // side of a pedestal just below a target is near the target's underside, but faces another way,
      // and would otherwise pull the estimate down onto it.
      const CloudN::Ptr source = with_normals(near, cfg.normal_neighbours, cfg.pcl_search);
      if (source->size() < cfg.min_points) {
        converged = false;
        break;
      }
      const bool last = stage + 1 == cfg.icp_distances_m.size();
      CountingIcp icp(cfg.point_to_plane, hold_weak && last);
      if (cfg.max_normal_angle_deg < 180.0) {
        auto normals = pcl::make_shared<pcl::registration::CorrespondenceRejectorSurfaceNormal>();
        normals->setThreshold(std::cos(config::radians(cfg.max_normal_angle_deg)));
        icp.addCorrespondenceRejector(normals);
      }
      if (cfg.icp_median_factor > 0.0) {  // PCL compares squared distances
        auto median = pcl::make_shared<pcl::registration::CorrespondenceRejectorMedianDistance>();
        median->setMedianFactor(cfg.icp_median_factor * cfg.icp_median_factor);
        icp.addCorrespondenceRejector(median);
      }
      icp.setInputSource(source);
      icp.setInputTarget(model_icp);
      icp.setSearchMethodTarget(model_icp_tree, true);
      icp.setMaxCorrespondenceDistance(distance);
      icp.setMaximumIterations(last ? cfg.icp_iterations : std::min(cfg.icp_iterations, cfg.coarse_iterations));
      const double step_m = last ? cfg.fine_step_m : std::max(cfg.fine_step_m, cfg.coarse_step_ratio * distance);
      icp.setTransformationEpsilon(step_m * step_m);
      icp.setEuclideanFitnessEpsilon(1e-12);
      CloudN aligned;
      icp.align(aligned, T_model_scan);
      iterations += icp.iterations();
      // PCL's flag says only whether its iterations stopped by a step or a count; the gate judges the
      // result (a right pose started at the truth ends with 0 iterations and 'not converged').
      converged = converged && (!cfg.icp_flag_decides || icp.hasConverged());
      T_model_scan = icp.getFinalTransformation();
      if (held && last) *held = icp.held();
    }
    return rigid_inverse(T_model_scan.cast<double>());
  }

  // A scan point at range z is explained within this of the model: the fixed inlier distance, or the
  // sensor's noise there when that is more.
  double tolerance_m(float z) const {
    const double zz = static_cast<double>(z) * z;
    return std::max(cfg.inlier_distance_m, cfg.inlier_sigmas * cfg.depth_sigma_coeff * zz);
  }

  // Where the ray from `viewpoint` through q (both in the model frame) first meets the model's surface,
  // as a distance along it from the viewpoint; infinity where it misses. Sphere tracing on the ICP
  // samples (spacing voxel_m) through the model's bounding sphere.
  float first_hit(const Eigen::Vector3f& q, const Eigen::Vector3f& viewpoint) const {
    const Eigen::Vector3f dir = (q - viewpoint).normalized();
    const float along = (extent.centroid - viewpoint).dot(dir);
    const float miss2 = (extent.centroid - viewpoint - along * dir).squaredNorm();
    const auto radius = static_cast<float>(extent.radius) + static_cast<float>(cfg.voxel_m);
    if (miss2 >= radius * radius) return std::numeric_limits<float>::infinity();
    const float half = std::sqrt(radius * radius - miss2);
    const auto hit = static_cast<float>(cfg.voxel_m);
    PointN x;
    pcl::Indices index(1);
    std::vector<float> dist2(1);
    for (float t = std::max(0.0F, along - half); t < along + half;) {
      x.getVector3fMap() = viewpoint + t * dir;
      if (model_icp_tree->nearestKSearch(x, 1, index, dist2) < 1) break;
      const float d = std::sqrt(dist2[0]);
      if (d < hit) return t;
      t += std::max(d - hit, 0.5F * hit);
    }
    return std::numeric_limits<float>::infinity();
  }

  // Whether a scan point the model does not explain says nothing about the pose: it stands in front of
  // the model along its ray (an occluder: a neighbour leaning on the target, a box on top of it), or
  // its ray misses the model and it lies farther than the model's surface beside it (a neighbour or
  // the background behind the target's outline) or more than kBesideReach tolerances from that surface
  // (a neighbour the target touches, seen at its depth: the wood block under the leaning banana; only for
  // a `close` guess, from a farther one a wrong estimate on a neighbour would pass by it too). A point
  // seen through the model, or beside it near its surface and at its depth (the target's own surface
  // outside a shifted estimate), counts against.
  bool neutral(const Eigen::Vector3f& q, const Eigen::Vector3f& viewpoint, double tolerance, bool close) const {
    const float range = (q - viewpoint).norm();
    const float t = first_hit(q, viewpoint);
    if (std::isfinite(t)) return t > range + static_cast<float>(tolerance);
    // Beside the outline: against the nearest of the model's samples that face the viewpoint (its seen
    // surface; a neighbour touching the target's far side is as far as that side).
    PointN x;
    x.getVector3fMap() = q;
    pcl::Indices index;
    std::vector<float> dist2;
    model_icp_tree->nearestKSearch(x, 16, index, dist2);
    for (const auto i : index) {
      const PointN& m = (*model_icp)[static_cast<std::size_t>(i)];
      const Eigen::Vector3f to_view = viewpoint - m.getVector3fMap();
      if (m.getNormalVector3fMap().dot(to_view) <= 0.0F) continue;
      if (close && (m.getVector3fMap() - q).norm() > kBesideReach * static_cast<float>(tolerance)) return true;
      return range > to_view.norm() + static_cast<float>(tolerance);
    }
    return true;  // only the model's far side near it: behind what the camera sees of the model
  }

  // Whether q (model frame) lies on the model: within `tolerance` of the nearest sample's plane (and
  // within twice that of the sample); `d` is that point-to-plane distance.
  bool explained(const PointN& q, double tolerance, double& d) const {
    pcl::Indices index(1);
    std::vector<float> dist2(1);
    if (model_tree->nearestKSearch(q, 1, index, dist2) < 1) return false;
    if (dist2[0] > static_cast<float>(4.0 * tolerance * tolerance)) return false;
    const PointN& m = (*model)[static_cast<std::size_t>(index[0])];
    d = std::abs((q.getVector3fMap() - m.getVector3fMap()).dot(m.getNormalVector3fMap()));
    return d <= tolerance;
  }

  // Quality of a pose: scan points near the posed model are inliers when their point-to-plane distance
  // to the nearest model sample is within their tolerance (tolerance_m). Scan points in front of the
  // model along their rays, or beyond its outline (scan_from_origin: neutral()), count for nothing.
  void evaluate(const pcl::PointCloud<pcl::PointXYZ>& near, const Eigen::Matrix4d& T, AlignmentResult& r, bool close) const {
    r.scan_points = near.size();
    if (near.empty()) {
      r.inlier_ratio = 0.0;
      r.rmse_mm = std::numeric_limits<double>::infinity();
      return;
    }
    const Eigen::Matrix4f inv = rigid_inverse(T).cast<float>();
    const Eigen::Vector3f viewpoint = inv.topRightCorner<3, 1>();  // the scan's origin in the model frame
    std::size_t inliers = 0, neutrals = 0;
    double sum2 = 0.0, scale_sum = 0.0, d = 0.0;
    for (const auto& p : near) {
      PointN q;
      q.getVector3fMap() = (inv * Eigen::Vector4f(p.x, p.y, p.z, 1.0F)).head<3>();
      if (!q.getVector3fMap().allFinite()) continue;
      const double tolerance = tolerance_m(p.z);
      scale_sum += tolerance / cfg.inlier_distance_m;
      if (!explained(q, tolerance, d)) {
        if (cfg.scan_from_origin && neutral(q.getVector3fMap(), viewpoint, tolerance, close)) ++neutrals;
        continue;
      }
      ++inliers;
      sum2 += d * d;
    }
    const std::size_t judged = near.size() - neutrals;
    r.inlier_ratio = judged > 0 ? static_cast<double>(inliers) / static_cast<double>(judged) : 0.0;
    r.neutral_ratio = static_cast<double>(neutrals) / static_cast<double>(near.size());
    r.rmse_mm = inliers > 0 ? 1000.0 * std::sqrt(sum2 / static_cast<double>(inliers)) : std::numeric_limits<double>::infinity();
    r.tolerance_scale = std::max(1.0, scale_sum / static_cast<double>(near.size()));
  }

  bool passes(const AlignmentResult& r) const {
    return r.inlier_ratio >= cfg.min_inlier_ratio && r.rmse_mm <= cfg.max_rmse_mm * r.tolerance_scale &&
           r.neutral_ratio <= cfg.max_neutral_ratio;
  }

  // The model's lowest point (over all its samples, as footing_in_camera measures it) above the
  // footing's floor under T.
  double lowest(const Footing& footing, const Eigen::Matrix4d& T) const {
    const Eigen::Matrix3d R = T.topLeftCorner<3, 3>();
    const Eigen::Vector3d t = T.topRightCorner<3, 1>();
    double h = std::numeric_limits<double>::infinity();
    for (const auto& p : *model) h = std::min(h, footing.floor.height_of(R * p.getVector3fMap().cast<double>() + t));
    return h;
  }

  // T stood on its footing: turned about the model's centre (the least turn) until upright, then moved
  // along the floor's normal to the surveyed height. What remains for ICP is where on the floor and
  // which way round: a gross guess tilted 40 degrees loses most of its error here.
  Eigen::Matrix4d stood(const Footing& footing, const Eigen::Matrix4d& T) const {
    if (!footing.upright_known) {  // only the height is known: moved onto the support, not turned
      Eigen::Matrix4d out = T;
      out.topRightCorner<3, 1>() += footing.floor.normal * (footing.height_m - lowest(footing, out));
      return out;
    }
    const Eigen::Vector3d up = (T.topLeftCorner<3, 3>() * footing.up_model).normalized();
    const Eigen::Vector3d c = extent.centre_in(T);
    Eigen::Matrix4d turn = Eigen::Matrix4d::Identity();
    // (Eigen's Quaternion::FromTwoVectors would do; its SVD trips GCC 12's use-after-free warning here.)
    const Eigen::Vector3d axis = up.cross(footing.floor.normal);
    const double angle = std::atan2(axis.norm(), up.dot(footing.floor.normal));
    const Eigen::Vector3d about = axis.norm() > 1e-9 ? axis.normalized() : up.unitOrthogonal();
    turn.topLeftCorner<3, 3>() = Eigen::AngleAxisd(angle, about).toRotationMatrix();
    turn.topRightCorner<3, 1>() = c - turn.topLeftCorner<3, 3>() * c;
    Eigen::Matrix4d out = turn * T;
    out.topRightCorner<3, 1>() += footing.floor.normal * (footing.height_m - lowest(footing, out));
    return out;
  }

  // Whether the model under r.T_scan_model stands as `footing` says: its lowest point at the surveyed
  // height, upright. Fills r's footing numbers.
  bool stands(const Footing& footing, AlignmentResult& r) const {
    const double h = lowest(footing, r.T_scan_model);
    const Eigen::Vector3d up = r.T_scan_model.topLeftCorner<3, 3>() * footing.up_model;
    const double cosine = std::clamp(up.normalized().dot(footing.floor.normal), -1.0, 1.0);
    r.footing_height_error_mm = 1000.0 * (h - footing.height_m);
    r.footing_tilt_deg = config::degrees(std::acos(cosine));
    const double above = h - footing.height_m;
    // A support found in the frame says the target rests on it: not floating above it.
    const double float_limit = footing.upright_known ? cfg.footing_height_m : cfg.support_float_m;
    r.stands = above <= float_limit && -above <= cfg.footing_height_m &&
               (!footing.upright_known || r.footing_tilt_deg <= cfg.footing_tilt_deg);
    return r.stands;
  }

  // Depth may leave how high a target stands free: a marker standing upright, its cap hardly measured,
  // slid 7 mm up its own axis and floated above the support found in the frame. Where the support can
  // say, it does: a pose floating above a frame's support by at most twice the float it may have (a
  // slide of a few millimetres) is put down onto it, along its normal, when the depth agrees there as
  // well, as colour's moves along weak directions are judged (the gate passes, at most 2 % fewer points
  // explained, the RMS error at most 10 % larger). A pose the depth pins (a mug lifted by its neighbours)
  // loses its fit when moved, and stays refused; one pulled farther up (the wood block, 17-19 mm by the
  // box it carries) is not put down: found there, the block lay 10-20 mm off, where a later search finds it.
  bool put_down(const PointCloud& scan, const Footing& footing, bool close_guess, AlignmentResult& r) const {
    if (footing.upright_known || !(r.footing_height_error_mm > 0.0) || r.footing_height_error_mm > 2000.0 * cfg.support_float_m)
      return false;
    AlignmentResult down = r;
    down.T_scan_model = stood(footing, r.T_scan_model);
    evaluate(*near_scan(scan, down.T_scan_model, gate_margin()), down.T_scan_model, down, close_guess);
    if (!stands(footing, down) || !passes(down) || down.inlier_ratio < r.inlier_ratio - 0.02 || down.rmse_mm > 1.1 * r.rmse_mm)
      return false;
    r = down;
    return true;
  }

  // The scan within `margin` of the model's sphere under T_init, on the coarse grid, thinned by a coarser
  // grid until at most max_global_points remain: what a bounded global search works on.
  pcl::PointCloud<pcl::PointXYZ>::Ptr global_points(const PointCloud& scan, const Eigen::Matrix4d& T_init, double margin,
                                                    std::size_t max_points) const {
    const Eigen::Vector3f centre = extent.centre_in(T_init).cast<float>();
    const double radius = cfg.crop ? extent.radius + margin : 0.0;
    double leaf = coarse_leaf();
    auto points = prepare(scan, centre, radius, leaf);
    while (points->size() > max_points && leaf < 0.05) points = prepare(scan, centre, radius, leaf *= 1.4);
    return points;
  }

  // Global re-initialisation: FPFH correspondences and SampleConsensusPrerejective over a wide region.
  std::optional<Eigen::Matrix4d> reinitialise(const PointCloud& scan, const Eigen::Matrix4d& T_init, double margin,
                                              std::size_t max_points, const std::function<bool()>& out_of_time) const {
    const auto wide_points = global_points(scan, T_init, margin, max_points);
    if (wide_points->size() < cfg.min_points) return std::nullopt;
    const CloudN::Ptr wide = with_normals(wide_points, cfg.normal_neighbours, cfg.pcl_search);
    if (!model_features) {
      model_features = fpfh(model_coarse, cfg.feature_radius_m, cfg.pcl_search);
      ++feature_computations;
    }
    const Features::Ptr scan_features = fpfh(wide, cfg.feature_radius_m, cfg.pcl_search);
    pcl::SampleConsensusPrerejective<PointN, PointN, pcl::FPFHSignature33> sac;
    sac.setInputSource(model_coarse);
    sac.setSourceFeatures(model_features);
    sac.setInputTarget(wide);
    sac.setTargetFeatures(scan_features);
    sac.setNumberOfSamples(3);
    sac.setCorrespondenceRandomness(5);
    sac.setSimilarityThreshold(0.85F);
    sac.setMaxCorrespondenceDistance(2.0 * coarse_leaf());
    sac.setInlierFraction(0.2F);
    // In rounds of at most 2000 iterations, so that a bounded attempt stops at its deadline (PCL's
    // RANSAC has no time limit: 20000 iterations on a planar scene took up to 10 s).
    CloudN aligned;
    for (int done = 0; done < cfg.ransac_iterations && !out_of_time(); done += 2000) {
      sac.setMaximumIterations(std::min(2000, cfg.ransac_iterations - done));
      sac.align(aligned);
      if (sac.hasConverged()) return sac.getFinalTransformation().cast<double>();
    }
    return std::nullopt;
  }
};

Aligner::Aligner(ModelCloud model, AcquisitionConfig config) : impl_(std::make_unique<Impl>()) {
  // PCL prints its own complaints ("Not enough correspondences found") to stderr; the result struct
  // carries every outcome, so keep the console for our messages.
  pcl::console::setVerbosityLevel(pcl::console::L_ALWAYS);
  impl_->cfg = config;
  impl_->extent = Extent(model.points);
  const std::string named = model.source.empty() ? std::string("model") : model.source + ": the model";
  if (model.points.size() < 10 || model.normals.size() != model.points.size())
    throw AlignmentError(named + " needs at least 10 points, each with a normal (got " + std::to_string(model.points.size()) +
                         ")");
  impl_->model = pcl::make_shared<CloudN>();
  for (std::size_t i = 0; i < model.points.size(); ++i) {
    if (!model.points[i].allFinite() || !model.normals[i].allFinite())
      throw AlignmentError(named + "'s point " + std::to_string(i) + " is not finite");
    PointN p;
    p.getVector3fMap() = model.points[i];
    p.getNormalVector3fMap() = model.normals[i];
    impl_->model->push_back(p);
  }
  impl_->model_tree = search_tree<PointN>(config.pcl_search);
  impl_->model_tree->setInputCloud(impl_->model);
  impl_->model_icp = voxel_downsample(impl_->model, config.voxel_m);
  impl_->model_icp_tree = search_tree<PointN>(config.pcl_search);
  impl_->model_icp_tree->setInputCloud(impl_->model_icp);
  impl_->model_coarse = voxel_downsample(impl_->model, impl_->coarse_leaf());
}

Aligner::~Aligner() = default;
Aligner::Aligner(Aligner&&) noexcept = default;
Aligner& Aligner::operator=(Aligner&&) noexcept = default;
const AcquisitionConfig& Aligner::config() const { return impl_->cfg; }

AlignmentResult Aligner::score(const PointCloud& scan, const Eigen::Matrix4d& T_scan_model, const std::optional<Footing>& footing,
                               bool close_guess) const {
  AlignmentResult r;
  r.T_scan_model = T_scan_model;
  impl_->evaluate(*impl_->near_scan(scan, T_scan_model, impl_->gate_margin()), T_scan_model, r, close_guess);
  const bool stands = !footing || impl_->stands(*footing, r);  // its numbers are wanted whether the gate passes or not
  r.converged = impl_->passes(r) && stands;
  return r;
}

int Aligner::model_feature_computations() const { return impl_->feature_computations; }

namespace {

// Keeps the better of two results: passing the gate first, then more inliers, then a lower RMSE.
bool better_than(const AlignmentResult& r, const AlignmentResult& best) {
  return (r.converged && !best.converged) ||
         (r.converged == best.converged &&
          (r.inlier_ratio > best.inlier_ratio + 0.02 || (r.inlier_ratio > best.inlier_ratio - 0.02 && r.rmse_mm < best.rmse_mm)));
}

}  // namespace

AlignmentResult Aligner::align(const PointCloud& scan, const Eigen::Matrix4d& T_init, SearchStage stage,
                               const std::optional<Footing>& footing, bool hold_weak,
                               std::optional<ThreadCpuClock::time_point> deadline, bool close_guess) const {
  const auto t0 = std::chrono::steady_clock::now();
  const Impl& m = *impl_;
  if (!T_init.allFinite()) throw AlignmentError("initial guess is not finite");
  const std::size_t valid = scan.finite_count();
  if (valid < m.cfg.min_points)
    throw AlignmentError("scan has " + std::to_string(valid) + " valid points; at least " + std::to_string(m.cfg.min_points) +
                         " are needed");

  // A bounded stage stops starting new work once attempt_budget_ms has passed; `full` runs to the end;
  // any stage at the caller's deadline.
  const auto out_of_time = [&] {  // a stop asked of the process ends the search as its deadline would
    if (ThreadCpuClock::past(deadline) || config::stop_requested()) return true;
    return stage != SearchStage::full && stage != SearchStage::icp_only && config::ms_since(t0) > m.cfg.attempt_budget_ms;
  };
  AlignmentResult best;
  best.T_scan_model = T_init;
  best.inlier_ratio = 0.0;
  best.rmse_mm = std::numeric_limits<double>::infinity();
  // With a footing every start is stood on it first: ICP then has only its place and heading to find.
  const auto attempt = [&](const Eigen::Matrix4d& start, bool reinitialised) {
    AlignmentResult r;
    bool icp_converged = false;
    const std::size_t first_stage = stage == SearchStage::finish ? m.cfg.icp_distances_m.size() - 1 : 0;
    int held = 0;
    r.T_scan_model = m.icp(scan, footing ? m.stood(*footing, start) : start, best.iterations, icp_converged, out_of_time,
                           first_stage, hold_weak, &held);
    r.weak_held = held > 0;
    r.reinitialised = reinitialised;
    m.evaluate(*m.near_scan(scan, r.T_scan_model, m.gate_margin()), r.T_scan_model, r, close_guess);
    bool stands = !footing || m.stands(*footing, r);
    if (!stands && footing) stands = m.put_down(scan, *footing, close_guess, r);
    r.converged = icp_converged && m.passes(r) && stands;
    r.iterations = best.iterations;
    if (better_than(r, best)) best = r;
  };
  const bool local = stage == SearchStage::full || stage == SearchStage::refine || stage == SearchStage::icp_only ||
                     stage == SearchStage::local || stage == SearchStage::finish;
  if (local) attempt(T_init, false);
  if (!best.converged && m.cfg.restart_angle_deg > 0.0 && (stage == SearchStage::full || stage == SearchStage::local)) {
    // Local restarts: the guess turned about the target's centre, which ICP alone cannot leave; about
    // each camera axis, or with a footing (upright is known) about the floor's normal by one and two steps.
    const Eigen::Vector3d c = m.extent.centre_in(T_init);
    std::vector<Eigen::AngleAxisd> turns;
    const double step = config::radians(m.cfg.restart_angle_deg);
    for (int i = 0; i < 3; ++i)
      for (const double sign : {1.0, -1.0})
        if (!footing || !footing->upright_known)
          turns.emplace_back(sign * step, Eigen::Vector3d::Unit(i));
        else if (i < 2)
          turns.emplace_back(sign * step * (i + 1), footing->floor.normal);
    for (const auto& axis_angle : turns) {
      if (best.converged || out_of_time()) break;
      Eigen::Matrix4d turn = Eigen::Matrix4d::Identity();
      turn.topLeftCorner<3, 3>() = axis_angle.toRotationMatrix();
      turn.topRightCorner<3, 1>() = c - turn.topLeftCorner<3, 3>() * c;
      attempt(turn * T_init, false);
    }
  }
  // Global re-initialisation: in `full` after the local attempts failed (as many points as the region
  // holds on the coarse grid, up to about max_scan_points, unless there is a deadline); as a stage of
  // its own, bounded by max_global_points. None once out of time: FPFH cannot stop half-way.
  const bool global = m.cfg.reinitialise && ((stage == SearchStage::full && !best.converged) ||
                                             stage == SearchStage::global_near || stage == SearchStage::global_wide);
  if (global && !out_of_time()) {
    const double margin = stage == SearchStage::global_wide ? m.cfg.wide_crop_margin_m : m.cfg.reinit_crop_margin_m;
    const std::size_t cap =
        stage == SearchStage::full && !deadline ? std::numeric_limits<std::size_t>::max() : m.cfg.max_global_points;
    if (const auto T = m.reinitialise(scan, T_init, margin, cap, out_of_time)) attempt(*T, true);
  }
  best.time_ms = config::ms_since(t0);
  return best;
}

}  // namespace projbot::alignment
