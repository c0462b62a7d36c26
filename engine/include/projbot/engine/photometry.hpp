#pragma once
// What a visitor sees (issue 43): the projector's light on a surface of known reflectance, pose and room
// light, and the input that makes that surface show the content. One model serves the twin's visitor
// (forward) and the renderer's compensation (inverse, here as the CPU reference of mesh.frag).
//
// Light, per channel: a surface of reflectance rho lit by E lux is seen as rho E / kReferenceLux (linear,
// 1 = a white surface under the reference light). The projector adds E_p = white_lux(q, n) M drive(c), where
// drive(c) = black + (1 - black) c^gamma per channel, M its colour mixing, and white_lux spreads its lumens over its
// pixels: a pixel's footprint on a plane facing the lens at depth z is (z / fx)(z / fy), tilted by the
// surface's incidence. Content c (sRGB) should be seen as k linear(c): the content under the reference
// light, scaled by the target's gain k (< 1 where the projector cannot make it brighter).

#include <Eigen/Core>
#include <array>
#include <limits>
#include <memory>
#include <optional>
#include <vector>

#include "projbot/assets/model.hpp"
#include "projbot/config/scene.hpp"

namespace projbot::engine {

/// The light that a white surface is seen by at 1.0: what "the content under the reference light" means.
constexpr double kReferenceLux = 1000.0;

/// sRGB's transfer (IEC 61966-2-1), 0..1 both ways.
double srgb_to_linear(double c);
double linear_to_srgb(double l);

/// brightness_lm fx fy / (W H): full white's lux at depth z = 1 m on a surface facing the lens, lux m^2.
double white_gain(const config::ProjectorConfig& projector);
/// Full white's lux on a surface at projector-frame point q (metres, z > 0) with normal n (either sign);
/// 0 behind the projector or edge-on.
double white_lux(const config::ProjectorConfig& projector, const Eigen::Vector3d& q, const Eigen::Vector3d& n);
/// Each channel's drive for input c (0..1 per channel), of its full light: black + (1 - black) c^gamma.
Eigen::Vector3d drive(const config::Photometry& photometry, const Eigen::Vector3d& c);
/// The projector's light in R, G, B for input c, of full white's: its mixing of the channels' drives.
Eigen::Vector3d light(const config::Photometry& photometry, const Eigen::Vector3d& c);

/// A drawn target's compensation: its surface shows content c as k linear(c). Off: the content is sent as
/// stored.
struct Compensation {
  bool on = false;
  std::array<float, 3> scale_lux{};  ///< k kReferenceLux / albedo per channel: the lux that content 1 needs
  float ambient_lux = 0.0F;          ///< the room's light, which the projector need not add
};
/// The compensation for a target of reflectance `albedo` seen with gain k in `ambient_lux`.
Compensation compensation(const Eigen::Vector3d& albedo, double ambient_lux, double k);

/// The input (0..1 per channel, clamped) that makes point q (normal n, projector frame) show content c
/// (sRGB, 0..1) under `comp`: mesh.frag's compensation, on the CPU. `clipped` (when given): whether a
/// channel needed more than full white or less than black.
Eigen::Vector3d compensated_input(const config::ProjectorConfig& projector, const Compensation& comp, const Eigen::Vector3d& c,
                                  const Eigen::Vector3d& q, const Eigen::Vector3d& n, bool* clipped = nullptr);

/// A point of a target's surface as the projector sees it now: its content (sRGB) and full white's lux there.
struct SurfaceSample {
  Eigen::Vector3d content = Eigen::Vector3d::Ones();
  double white_lux = 0.0;
  double weight = 1.0;                                    ///< its share of the projector's pixels: the solid angle it fills, sr
  Eigen::Vector3d reflectance = Eigen::Vector3d::Ones();  ///< the surface texture's there (linear); 1 without one
};
/// The target's triangles that face the projector at T_projector_target, their middle inside its image:
/// each one's content (material, texture at its corners' UVs, vertex colours; averaged), its surface
/// texture's reflectance likewise (`surface`, sRGB over the same UVs, repeating; null: none) and full
/// white's lux at its middle, weighted by the projector pixels it covers (so that grazing slivers count little).
std::vector<SurfaceSample> surface_samples(const assets::Model& model, const config::ProjectorConfig& projector,
                                           const Eigen::Matrix4d& T_projector_target, const assets::Image* surface = nullptr);
/// The target's gain k: the largest that leaves at most `clip_share` of `samples`' weight asking a channel
/// for more than full white (albedo times each sample's reflectance, ambient as above), at most 1 (the
/// content under the reference light); 1 when nothing asks. Chosen once per visit, so frames do not flicker.
double choose_gain(const std::vector<SurfaceSample>& samples, const Eigen::Vector3d& albedo, double ambient_lux,
                   double clip_share = 0.02, const Eigen::Matrix3d& mixing = Eigen::Matrix3d::Identity());

/// A target's reflectance per channel, measured at a stop (issue 43): the colour camera's images of it
/// under the projector's black and its uniform `grey` input (sRGB, registered to `camera`; a
/// radiometrically calibrated camera, on which a white surface under kReferenceLux reads 1) and its
/// estimated pose in the camera's and the projector's frames. Points spread over each triangle that faces
/// both, lit less than 60 degrees off its normal (about one per 4 x 4 camera pixels), give (grey - black)
/// kReferenceLux / ((drive(grey) - drive(0)) white_lux) at their pixels (the room's light cancels); the
/// median over them per channel. Empty when fewer than 20 points can be read unsaturated.
std::optional<Eigen::Vector3d> measure_albedo(const assets::Model& model, const config::Camera& camera,
                                              const Eigen::Matrix4d& T_camera_target, const config::ProjectorConfig& projector,
                                              const Eigen::Matrix4d& T_projector_target, const assets::Image& under_black,
                                              const assets::Image& under_grey, double grey);

/// One point of a target's surface as measure_albedo reads it: where it lies in the model's texture
/// coordinates and its reflectance per channel there (valid: the grey picture was not saturated).
struct ReflectancePoint {
  Eigen::Vector2d uv = Eigen::Vector2d::Zero();
  Eigen::Vector3d rho = Eigen::Vector3d::Zero();
  std::array<bool, 3> valid{};
};
/// The points measure_albedo takes its medians over (the same arguments); empty for pictures it cannot read.
std::vector<ReflectancePoint> reflectance_points(const assets::Model& model, const config::Camera& camera,
                                                 const Eigen::Matrix4d& T_camera_target, const config::ProjectorConfig& projector,
                                                 const Eigen::Matrix4d& T_projector_target, const assets::Image& under_black,
                                                 const assets::Image& under_grey, double grey);

/// The median reflectance of `points` per channel (measure_albedo's); empty where a channel has fewer than 20.
std::optional<Eigen::Vector3d> median_albedo(const std::vector<ReflectancePoint>& points);

/// A target's reflectance measured into its model's texture space (issue 43, a printed surface learnt at its
/// stops): each texel the median of the newest kPerTexel values that fell in it (refined over visits,
/// following a surface that changes; of one measurement's many in a texel, kPerTexel spread over them), grown into the texels
/// none fell in from their nearest measured ones in texture space, and the median of the newest kFillPoints points where none
/// reaches (a chart never seen). Its memory is bounded however long the tour. Its image is a surface texture
/// (Renderer::set_surface).
class ReflectanceMap {
 public:
  static constexpr std::size_t kPerTexel = 32;
  static constexpr std::size_t kFillPoints = 200000;
  ReflectanceMap(int width = 128, int height = 128);
  void add(const std::vector<ReflectancePoint>& points);
  /// sRGB, width x height, repeating over the UVs; empty while a channel has fewer than 20 points.
  std::optional<assets::Image> image() const;
  /// The median of the newest kFillPoints points per channel (what fills the texels none reached); empty
  /// while a channel has fewer than 20.
  std::optional<Eigen::Vector3d> median() const { return median_albedo(recent_); }
  /// The values it holds: at most kPerTexel per texel and channel, plus kFillPoints points.
  std::size_t values_kept() const;

 private:
  struct Texel {
    std::array<std::vector<float>, 3> values;  ///< per channel, the newest kPerTexel kept (a ring once full)
    std::array<std::size_t, 3> kept{};         ///< per channel, every value kept so far
  };
  std::size_t texel_of(const ReflectancePoint& p) const;
  int width_, height_;
  std::vector<Texel> texels_;
  std::vector<ReflectancePoint> recent_;  ///< the newest kFillPoints points (a ring once full)
  std::size_t added_ = 0;                 ///< every point added
};

/// The compensation of each target a session draws (issue 43): a target's gain is chosen the first time it
/// is drawn in a visit, from its surface at that pose. Given the frames' times, it then follows the pose:
/// chosen again every kRechooseS, and once that choice differs from the gain in use by more than
/// kDeadband, the gain moves to it by at most kRatePerS (relative, per second), so a target that turns
/// towards grazing light dims over a second instead of clipping, and nothing flickers frame to frame.
/// Without times, the visit's first gain is kept. Off: every target's content as stored. One thread (the
/// render thread, or the tour's).
class CompensationPlan {
 public:
  struct Target {
    const assets::Model* model = nullptr;  ///< its content; must outlive the plan
    Eigen::Vector3d albedo = Eigen::Vector3d::Constant(0.75);
    /// Its surface texture (`surface.texture`, bound to its model by Renderer::set_surface), with an
    /// albedo of 1: the gain choice reads it; null: `albedo` everywhere.
    std::shared_ptr<const assets::Image> surface;
  };
  CompensationPlan(std::vector<Target> targets, double ambient_lux, bool on);
  static constexpr double kRechooseS = 0.1;
  static constexpr double kDeadband = 0.05;
  static constexpr double kRatePerS = 0.5;
  /// Target `target`'s compensation in visit `visit` (any number that changes between visits), drawn at
  /// T_projector_target through `projector`, displayed at `display_s` (seconds on any steady clock; NaN:
  /// the gain is not followed).
  Compensation at(std::size_t target, long visit, const config::ProjectorConfig& projector,
                  const Eigen::Matrix4d& T_projector_target, double display_s = std::numeric_limits<double>::quiet_NaN());
  /// A target's reflectance measured at a stop (measure_albedo): the mean of its measurements so far
  /// replaces the scene's from now on (refined over visits); its gain is chosen again. A target whose
  /// surface is a texture keeps it (one colour measured over it would blur its print).
  void add_measured_albedo(std::size_t target, const Eigen::Vector3d& albedo);
  const Eigen::Vector3d& albedo(std::size_t target) const { return targets_.at(target).albedo; }
  /// A target's surface measured into its texture space (ReflectanceMap::image): it replaces the scene's
  /// surface, its albedo becomes 1, and its gain is chosen again. Bind the same to its model
  /// (Renderer::set_surface).
  void set_surface(std::size_t target, std::shared_ptr<const assets::Image> surface);
  /// The gain chosen for `target` in its latest visit; 1 before any.
  double gain(std::size_t target) const { return chosen_.at(target).gain; }
  bool on() const { return on_; }

 private:
  struct Chosen {
    long visit = -1;
    double gain = 1.0;    // in use
    double wanted = 1.0;  // the latest choice
    double chosen_s = std::numeric_limits<double>::quiet_NaN(), used_s = std::numeric_limits<double>::quiet_NaN();
    bool made = false;
    bool adjusting = false;  // moving towards `wanted`
    int measurements = 0;    // add_measured_albedo's so far
  };
  double choose(std::size_t target, const config::ProjectorConfig& projector, const Eigen::Matrix4d& T_projector_target) const;
  void follow(Chosen& c, std::size_t target, const config::ProjectorConfig& projector, const Eigen::Matrix4d& T_projector_target,
              double display_s) const;
  std::vector<Target> targets_;
  std::vector<Chosen> chosen_;
  double ambient_lux_;
  bool on_;
};

}  // namespace projbot::engine
