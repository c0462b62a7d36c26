#pragma once
// What the visitor sees of a target against what it should show (issue 43): the content under the
// reference light scaled by the target's gain k, over the target's lit pixels of a spectator's picture.
// PSNR over 8-bit sRGB, SSIM (Wang et al. 2004: 11 x 11 Gaussian window, sigma 1.5, on luma), and CIEDE2000
// (Sharma, Wu and Dalal 2005) over the pixels whose reflectance lets the projector reach the content.

#include <Eigen/Core>
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "projbot/assets/image.hpp"
#include "projbot/config/scene.hpp"
#include "projbot/engine/photometry.hpp"
#include "projbot/live/rig.hpp"
#include "projbot/twin/spectator.hpp"

namespace projbot::twin {

/// CIE L*a*b* (D65) of an sRGB colour (0..1 per channel).
Eigen::Vector3d srgb_to_lab(const Eigen::Vector3d& srgb);
/// CIEDE2000 colour difference of two L*a*b* colours (kL = kC = kH = 1).
double ciede2000(const Eigen::Vector3d& lab1, const Eigen::Vector3d& lab2);

struct AppearanceScore {
  std::size_t pixels = 0;  ///< the target's lit pixels scored
  double psnr_db = 0.0, ssim = 0.0;
  double de2000_median = 0.0, de2000_p95 = 0.0;  ///< over the reachable pixels
  double clipped_share = 0.0;                    ///< pixels whose content needs more than full white there
  double unreachable_share = 0.0;                ///< clipped, or darker than the room's light and the projector's black allow
};

/// Scores `seen` (SpectatorView::see) against k x the content of `view` (SpectatorView::content), over the pixels of the target
/// that the projector reaches. `ambient_lux` and `photometry`: the room's and the projector's light, to
/// tell which pixels any projector input could make right.
AppearanceScore score_appearance(const SpectatorPicture& seen, const ContentView& view, double k, double ambient_lux,
                                 const config::Photometry& photometry);

/// Of a projector frame drawn with compensation (`on`) the share of the target's pixels at 254 or more in
/// some channel: clipped where the projector sends it. The target's pixels: those lit in `on` or in
/// `off`, the same frame drawn with the content as stored (drawn alone, without neighbours). 0 when none.
double saturated_share(const assets::Image& on, const assets::Image& off);

/// A target's reflectance as a session measures it at a stop (issue 43): the colour camera (`camera`, a
/// SpectatorView through the RGB-D camera's pinhole) takes it under the projector's black and mid grey,
/// lit by the twin from the true frames; engine::reflectance_points reads the pictures at the estimated
/// poses (T_camera_target, and T_projector_target through the believed projector). Empty when it cannot.
std::vector<engine::ReflectancePoint> measured_reflectance(SpectatorView& camera, Twin& twin, std::size_t target,
                                                           const Eigen::Matrix4d& T_world_camera,
                                                           const Eigen::Matrix4d& T_world_projector,
                                                           const Eigen::Matrix4d& T_camera_target,
                                                           const config::ProjectorConfig& believed,
                                                           const Eigen::Matrix4d& T_projector_target);

/// A session's learnt reflectance in the twin (`record`): at the end of each stop, every lit target whose
/// pose was accepted is measured at that pose (measured_reflectance: the RGB-D camera's colour under the
/// projector's black and mid grey, the projector as the scene believes it, Eq. 2) into a map over its
/// model's texture coordinates, refined over its visits. Renders on the twin's renderer's thread.
class ReflectanceSurvey final : public live::SurfaceSurvey {
 public:
  ReflectanceSurvey(Twin& twin, engine::Renderer& renderer);
  /// Measures scene target `name` at T_camera_target (its estimate, the twin's camera frame): the points
  /// read (0: none of it in the camera's view and the projector's light).
  std::size_t measure(const std::string& name, const Eigen::Matrix4d& T_camera_target) override;
  /// Each measured target's, by name; a target with too few points is left out.
  std::map<std::string, Learnt> learnt() const override;

 private:
  Twin& twin_;
  SpectatorView camera_;
  std::map<std::string, engine::ReflectanceMap> maps_;
};

}  // namespace projbot::twin
