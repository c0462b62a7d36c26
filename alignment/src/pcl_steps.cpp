// PCL's filters, normals and features as acquisition uses them; the model clouds built with them; and
// PCL's plain ICP, the baseline the projective tracker is measured against (bench track).

#include "pcl_steps.hpp"

#include <pcl/features/fpfh_omp.h>
#include <pcl/features/normal_3d.h>
#include <pcl/filters/statistical_outlier_removal.h>
#include <pcl/filters/voxel_grid.h>
#include <pcl/registration/icp.h>

#include <cmath>
#include <ctime>
#include <limits>

#include "file_kind.hpp"
#include "ply_body.hpp"
#include "projbot/alignment/equations.hpp"
#include "projbot/alignment/registration.hpp"
#include "projbot/alignment/verification.hpp"
#include "projbot/assets/model.hpp"

namespace projbot::alignment {
namespace detail {

CloudN::Ptr voxel_downsample(const CloudN::ConstPtr& in, double leaf) {
  auto out = pcl::make_shared<CloudN>();
  pcl::VoxelGrid<PointN> grid;
  grid.setInputCloud(in);
  grid.setLeafSize(static_cast<float>(leaf), static_cast<float>(leaf), static_cast<float>(leaf));
  grid.filter(*out);
  for (auto& p : *out) {  // averaged normals are no longer unit
    Eigen::Map<Eigen::Vector3f> n(p.normal);
    const float len = n.norm();
    if (len > 1e-6F) n /= len;
  }
  return out;
}

pcl::PointCloud<pcl::PointXYZ>::Ptr outliers_removed(const pcl::PointCloud<pcl::PointXYZ>::ConstPtr& in, int k,
                                                     double stddev_mul) {
  SerialKdTree<pcl::PointXYZ> tree;
  tree.setInputCloud(in);
  pcl::Indices nn;
  std::vector<float> d2;
  std::vector<float> mean_distance(in->size(), 0.0F);
  double sum = 0.0, sq_sum = 0.0;
  int valid = 0;
  for (std::size_t i = 0; i < in->size(); ++i) {
    if (tree.nearestKSearch((*in)[i], k + 1, nn, d2) == 0) continue;  // not finite
    double dist_sum = 0.0;
    for (std::size_t j = 1; j < d2.size(); ++j) dist_sum += std::sqrt(d2[j]);  // the first is the point itself
    mean_distance[i] = static_cast<float>(dist_sum / k);
    sum += mean_distance[i];
    sq_sum += mean_distance[i] * mean_distance[i];  // in float, as PCL
    ++valid;
  }
  auto kept = pcl::make_shared<pcl::PointCloud<pcl::PointXYZ>>();
  if (valid < 2) return kept;
  const double mean = sum / valid;
  const double stddev = std::sqrt((sq_sum - sum * sum / valid) / (valid - 1.0));
  const double threshold = mean + stddev_mul * stddev;
  kept->reserve(in->size());
  for (std::size_t i = 0; i < in->size(); ++i)
    if (mean_distance[i] <= threshold && pcl::isXYZFinite((*in)[i])) kept->push_back((*in)[i]);
  return kept;
}

pcl::PointCloud<pcl::PointXYZ>::Ptr pcl_outliers_removed(const pcl::PointCloud<pcl::PointXYZ>::ConstPtr& in, int k,
                                                         double stddev_mul) {
  auto kept = pcl::make_shared<pcl::PointCloud<pcl::PointXYZ>>();
  pcl::StatisticalOutlierRemoval<pcl::PointXYZ> sor;
  sor.setInputCloud(in);
  sor.setMeanK(k);
  sor.setStddevMulThresh(stddev_mul);
  sor.filter(*kept);
  return kept;
}

CloudN::Ptr with_normals(const pcl::PointCloud<pcl::PointXYZ>::ConstPtr& in, int k, bool pcl_search) {
  pcl::PointCloud<pcl::Normal> normals;
  pcl::NormalEstimation<pcl::PointXYZ, pcl::Normal> ne;
  ne.setInputCloud(in);
  ne.setSearchMethod(search_tree<pcl::PointXYZ>(pcl_search));
  ne.setKSearch(std::min<int>(k, static_cast<int>(in->size()) - 1));
  ne.setViewPoint(0.0F, 0.0F, 0.0F);
  ne.compute(normals);
  auto out = pcl::make_shared<CloudN>();
  out->reserve(in->size());
  for (std::size_t i = 0; i < in->size(); ++i) {
    if (!std::isfinite(normals[i].normal_x)) continue;
    PointN p;
    p.x = (*in)[i].x, p.y = (*in)[i].y, p.z = (*in)[i].z;
    p.normal_x = normals[i].normal_x, p.normal_y = normals[i].normal_y, p.normal_z = normals[i].normal_z;
    p.curvature = normals[i].curvature;
    out->push_back(p);
  }
  return out;
}

Features::Ptr fpfh(const CloudN::ConstPtr& cloud, double radius, bool pcl_search) {
  auto features = pcl::make_shared<Features>();
  pcl::FPFHEstimationOMP<PointN, PointN, pcl::FPFHSignature33> est;
  est.setInputCloud(cloud);
  est.setInputNormals(cloud);
  est.setSearchMethod(search_tree<PointN>(pcl_search));
  est.setRadiusSearch(radius);
  est.compute(*features);
  return features;
}

void DampedPointToPlane::estimateRigidTransformation(const pcl::PointCloud<PointN>& source, const pcl::PointCloud<PointN>& target,
                                                     const pcl::Correspondences& correspondences, Eigen::Matrix4f& T) const {
  if (hold_weak_) {
    T = strong_step(source, target, correspondences);
    return;
  }
  held_ = 0;
  Eigen::Matrix<double, 6, 6> ata = Eigen::Matrix<double, 6, 6>::Zero();
  Eigen::Matrix<double, 6, 1> atb = Eigen::Matrix<double, 6, 1>::Zero();
  for (const auto& c : correspondences) {
    const Eigen::Vector3d p = source[static_cast<std::size_t>(c.index_query)].getVector3fMap().cast<double>();
    const PointN& q = target[static_cast<std::size_t>(c.index_match)];
    const Eigen::Vector3d n = q.getNormalVector3fMap().cast<double>();
    if (!p.allFinite() || !n.allFinite()) continue;
    Eigen::Matrix<double, 6, 1> a;
    a << p.cross(n), n;
    ata += a * a.transpose();
    atb += a * n.dot(q.getVector3fMap().cast<double>() - p);
  }
  const double damping = 1e-9 + 1e-6 * ata.trace() / 6.0;
  const Eigen::Matrix<double, 6, 1> x = (ata + damping * Eigen::Matrix<double, 6, 6>::Identity()).ldlt().solve(atb);
  Eigen::Matrix4d out = Eigen::Matrix4d::Identity();
  if (x.allFinite()) {
    out.topLeftCorner<3, 3>() =
        (Eigen::AngleAxisd(x[2], Eigen::Vector3d::UnitZ()) * Eigen::AngleAxisd(x[1], Eigen::Vector3d::UnitY()) *
         Eigen::AngleAxisd(x[0], Eigen::Vector3d::UnitX()))
            .toRotationMatrix();
    out.topRightCorner<3, 1>() = x.tail<3>();
  }
  T = out.cast<float>();
}

Eigen::Matrix4f DampedPointToPlane::strong_step(const pcl::PointCloud<PointN>& source, const pcl::PointCloud<PointN>& target,
                                                const pcl::Correspondences& correspondences) const {
  std::vector<Eigen::Vector3d> points, normals;
  std::vector<double> distances;  // signed, to the model's plane
  for (const auto& c : correspondences) {
    const Eigen::Vector3d p = source[static_cast<std::size_t>(c.index_query)].getVector3fMap().cast<double>();
    const PointN& q = target[static_cast<std::size_t>(c.index_match)];
    const Eigen::Vector3d n = q.getNormalVector3fMap().cast<double>();
    if (!p.allFinite() || !n.allFinite()) continue;
    points.push_back(p);
    normals.push_back(n);
    distances.push_back(n.dot(q.getVector3fMap().cast<double>() - p));
  }
  const StrongStep step = strong_point_to_plane_step(points, normals, distances);
  held_ = step.held;
  return step.T.cast<float>();
}

}  // namespace detail

using detail::Extent;

struct PclIcpBaseline::Impl {
  explicit Impl(const ModelCloud& m) : extent(m.points) {}
  Extent extent;
  pcl::PointCloud<pcl::PointXYZ>::Ptr model;
  pcl::search::KdTree<pcl::PointXYZ>::Ptr model_tree;
  double voxel = 0.004;
  int iterations = 30;
  double max_distance = 0.04;
};

PclIcpBaseline::PclIcpBaseline(const ModelCloud& model, double voxel_m, int iterations, double max_distance_m)
    : impl_(std::make_unique<Impl>(model)) {
  auto raw = pcl::make_shared<pcl::PointCloud<pcl::PointXYZ>>();
  for (const auto& p : model.points) raw->push_back(pcl::PointXYZ(p.x(), p.y(), p.z()));
  if (raw->empty()) throw AlignmentError("baseline: empty model");
  impl_->model = pcl::make_shared<pcl::PointCloud<pcl::PointXYZ>>();
  pcl::VoxelGrid<pcl::PointXYZ> grid;
  grid.setInputCloud(raw);
  grid.setLeafSize(static_cast<float>(voxel_m), static_cast<float>(voxel_m), static_cast<float>(voxel_m));
  grid.filter(*impl_->model);
  impl_->model_tree = pcl::make_shared<pcl::search::KdTree<pcl::PointXYZ>>();
  impl_->model_tree->setInputCloud(impl_->model);
  impl_->voxel = voxel_m;
  impl_->iterations = iterations;
  impl_->max_distance = max_distance_m;
}
PclIcpBaseline::~PclIcpBaseline() = default;
PclIcpBaseline::PclIcpBaseline(PclIcpBaseline&&) noexcept = default;
PclIcpBaseline& PclIcpBaseline::operator=(PclIcpBaseline&&) noexcept = default;

Eigen::Matrix4d PclIcpBaseline::track(const PointCloud& scan, const Eigen::Matrix4d& T_init) const {
  const Eigen::Vector3f c = impl_->extent.centre_in(T_init).cast<float>();
  const float r2 = static_cast<float>(std::pow(impl_->extent.radius + 0.1, 2));
  auto raw = pcl::make_shared<pcl::PointCloud<pcl::PointXYZ>>();
  for (const auto& p : scan.points)
    if (p.allFinite() && (p - c).squaredNorm() <= r2) raw->push_back(pcl::PointXYZ(p.x(), p.y(), p.z()));
  if (raw->size() < 10) return T_init;
  // PCL at its best for tracking: the downsampled scan as source (all of it lies on the model), the
  // model as target with its search tree built once.
  auto source = pcl::make_shared<pcl::PointCloud<pcl::PointXYZ>>();
  pcl::VoxelGrid<pcl::PointXYZ> grid;
  grid.setInputCloud(raw);
  const auto leaf = static_cast<float>(impl_->voxel);
  grid.setLeafSize(leaf, leaf, leaf);
  grid.filter(*source);
  pcl::IterativeClosestPoint<pcl::PointXYZ, pcl::PointXYZ> icp;
  icp.setInputSource(source);
  icp.setInputTarget(impl_->model);
  icp.setSearchMethodTarget(impl_->model_tree, true);
  icp.setMaxCorrespondenceDistance(impl_->max_distance);
  icp.setMaximumIterations(impl_->iterations);
  icp.setTransformationEpsilon(1e-10);
  pcl::PointCloud<pcl::PointXYZ> aligned;
  icp.align(aligned, rigid_inverse(T_init).cast<float>());
  return rigid_inverse(icp.getFinalTransformation().cast<double>());
}

AcquisitionConfig pcl_pipeline_config(bool pcl_search) {
  AcquisitionConfig c;
  c.pcl_search = pcl_search;
  c.restart_angle_deg = 0.0;
  c.reinitialise = false;
  c.icp_flag_decides = true;
  c.min_inlier_ratio = 0.0;  // no gate: PCL reports convergence, not whether the pose is right
  c.max_rmse_mm = 1e9;
  c.scan_from_origin = false;
  c.icp_median_factor = 0.0;  // ICP as PCL sets it up: its distance threshold and nothing else
  return c;
}

Eigen::Vector3d centroid_of(const ModelCloud& model) {
  Eigen::Vector3d c = Eigen::Vector3d::Zero();
  for (const auto& p : model.points) c += p.cast<double>();
  return c / static_cast<double>(std::max<std::size_t>(model.points.size(), 1));
}

ModelCloud model_cloud_from(const assets::Model& model, std::size_t samples) {
  const auto s = assets::sample_surface(model, samples, 1);
  return {s.points, s.normals, s.colours, model.source};  // a refusal of the cloud names the file
}

namespace {

using detail::CloudN;
using detail::with_normals;

ModelCloud cloud_model(const std::filesystem::path& path) {
  const PointCloud cloud = finite_points(read_cloud(path));
  if (cloud.points.size() < 10)
    throw AlignmentError(path.string() + ": model cloud has " + std::to_string(cloud.points.size()) + " valid points");
  auto xyz = pcl::make_shared<pcl::PointCloud<pcl::PointXYZ>>();
  for (const auto& p : cloud.points) xyz->push_back(pcl::PointXYZ(p.x(), p.y(), p.z()));
  // Keep the cloud alive for the loop: a range-for over `*with_normals(...)` would read a freed cloud.
  const CloudN::Ptr with = with_normals(xyz, 16);
  ModelCloud m;
  for (const auto& p : *with) {
    m.points.push_back(p.getVector3fMap());
    m.normals.push_back(p.getNormalVector3fMap());
  }
  return m;
}

}  // namespace

ModelCloud load_model_cloud(const std::filesystem::path& path, std::size_t samples, double scale) {
  if (!(scale > 0.0) || !std::isfinite(scale) || scale < 1e-6 || scale > 1e6)
    throw AlignmentError(path.string() + ": model scale must be a finite number in [1e-6, 1e6], not " + std::to_string(scale));
  const std::string ext = detail::lower_extension(path);
  // A PLY is a mesh (sampled over its surface) when its header declares faces; the same walk checks its
  // body against its counts, which Assimp, like PCL, reads without looking at what follows them.
  const bool mesh = ext == ".gltf" || ext == ".glb" || ext == ".obj" || ext == ".stl" ||
                    (ext == ".ply" && detail::check_ply_body(path).faces > 0);
  if (mesh) {
    try {
      assets::Model model = assets::load_model(path);
      assets::scale_and_recenter(model, scale, false);
      ModelCloud m = model_cloud_from(model, samples);
      if (m.points.size() < 10) throw AlignmentError(path.string() + ": the model's surface has no area to sample");
      m.source = path.string();
      return m;
    } catch (const assets::AssetError& e) {
      throw AlignmentError(e.what());
    }
  }
  ModelCloud m = cloud_model(path);
  for (auto& p : m.points) p *= static_cast<float>(scale);
  m.source = path.string();
  return m;
}

Footing footing_in_camera(const ModelCloud& model, const Eigen::Matrix4d& T_world_target, const Eigen::Matrix4d& T_world_camera) {
  if (model.points.empty()) throw AlignmentError("the model has no points to find its lowest point from");
  if (!T_world_target.allFinite() || !T_world_camera.allFinite()) throw AlignmentError("the surveyed pose is not finite");
  Footing f;
  f.floor = floor_in_camera(T_world_camera);
  const Eigen::Matrix3d R = T_world_target.topLeftCorner<3, 3>();
  f.up_model = R.transpose() * Eigen::Vector3d::UnitZ();
  f.height_m = std::numeric_limits<double>::infinity();
  for (const auto& p : model.points) f.height_m = std::min(f.height_m, (R * p.cast<double>()).z() + T_world_target(2, 3));
  return f;
}

ThreadCpuClock::time_point ThreadCpuClock::now() noexcept {
  timespec ts{};
  ::clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return time_point(std::chrono::seconds(ts.tv_sec) + std::chrono::nanoseconds(ts.tv_nsec));
}

}  // namespace projbot::alignment
