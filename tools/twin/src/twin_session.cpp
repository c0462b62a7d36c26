#include "projbot/twin/twin_session.hpp"

#include <utility>

namespace projbot::twin {

TwinSession::TwinSession(const config::Scene& scene, const std::vector<session::Target>& targets, std::uint64_t seed,
                         alignment::RgbdCamera* configured, std::function<bool()> stop_requested, bool colour_every_frame,
                         const alignment::KinectNoiseConfig& depth_model)
    : renderer_(engine::RendererOptions{}),
      twin_(
          scene,
          [&] {
            TwinOptions o;
            o.seed = seed;
            o.depth_model = depth_model;
            o.stop_requested = std::move(stop_requested);  // SIGTERM while the twin is built
            return o;
          }(),
          renderer_),
      twin_camera_(twin_, seed, colour_every_frame),
      configured_(configured),
      session_(scene, targets, twin_.robot(), twin_.pan_tilt()) {}

session::Dwell TwinSession::dwell(double dwell_s, bool lockstep) {
  session::Dwell d;
  d.camera = [this](const session::Stop& stop, double since_s) -> alignment::RgbdCamera& {
    const std::size_t i = twin_.target_index(twin_.scene().targets[static_cast<std::size_t>(stop.target)].name);
    twin_camera_.at_stop(i, stop.target_visit, stop.visit, since_s);
    return configured_ ? *configured_ : twin_camera_;
  };
  d.over = [dwell_s](const session::Stop&, int, double elapsed_s) { return elapsed_s >= dwell_s; };
  d.lockstep = lockstep;
  return d;
}

}  // namespace projbot::twin
