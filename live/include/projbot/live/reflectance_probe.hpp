#pragma once
// A target's reflectance learnt by the live session at its stops (issue 43, item 3): once the visited
// target's pose is accepted, the projector shows black and then mid grey over its whole image (the render
// thread: ProjectionInputs::uniform) while the colour camera takes the target under each; the two pictures are
// read at the tracked pose (engine::reflectance_points: the light's distance and angle divided out, the
// room's light subtracted) into the target's map over its model's texture coordinates, refined over its
// visits, and handed to the render thread, which compensates with it from then on. Once per stop.

#include <Eigen/Core>
#include <array>
#include <atomic>
#include <cstdint>
#include <filesystem>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "projbot/alignment/rgbd_camera.hpp"
#include "projbot/assets/image.hpp"
#include "projbot/assets/model.hpp"
#include "projbot/config/scene.hpp"
#include "projbot/engine/photometry.hpp"
#include "projbot/live/projection_frames.hpp"
#include "projbot/live/stop_sequence.hpp"

namespace projbot::live {

class ReflectanceProbe {
 public:
  /// What one stop's measurement gave its target.
  struct Learnt {
    int target = -1;                                   ///< scene index
    std::shared_ptr<const assets::Image> map;          ///< over its texture coordinates; null: a model without them
    Eigen::Vector3d albedo = Eigen::Vector3d::Zero();  ///< the median of its points so far
    std::size_t points = 0;                            ///< this stop's
  };

  /// `models[i]`: scene target i's model (it must outlive the probe). Each image is taken once the colour
  /// camera's frames were captured `settle_s` after the colour was asked for (the projector's refresh and
  /// input lag, and the camera's exposure, must fit in it).
  ReflectanceProbe(const config::Scene& scene, std::vector<const assets::Model*> models, double settle_s);
  /// After each measurement, what was learnt so far written into `dir` (made then): each map as NAME.png
  /// and surfaces.yaml, each learnt target's `surface:` as a scene takes it (a map by its absolute path),
  /// both written whole and renamed. A failure to write is said, and the session goes on.
  void save_to(std::filesystem::path dir) { save_dir_ = std::move(dir); }

  // The robot thread, as a StopObserver's calls come.
  void lit(const live::Stop& stop, double since_s);
  /// A frame the camera handed over at the stop, `now_s` on the steady clock; `poses` the trackers' newest.
  /// Returns what it has to say (a measurement done or given up), or empty.
  std::string frame(const alignment::RgbdFrame& f, double now_s, const live::PoseSource& poses);
  void left();

  // The render thread.
  /// The colour the projector is to show over its whole image now, if any.
  std::optional<std::array<std::uint8_t, 3>> showing() const;
  /// What was learnt since the last call.
  std::vector<Learnt> take_learnt();

 private:
  enum class Phase { idle, black, grey, done };
  std::string measure(const alignment::RgbdFrame& grey, const alignment::PoseSample& pose);
  std::string save(const Learnt& l);
  void show(int level) { showing_.store(level); }

  const config::Scene& scene_;
  std::vector<const assets::Model*> models_;
  double settle_s_;
  std::atomic<int> showing_{-1};  // the level shown over the whole image; -1: the targets
  // The robot thread's.
  int target_ = -1;
  double since_s_ = 0.0, phase_s_ = 0.0;
  Phase phase_ = Phase::done;
  assets::Image black_;
  Eigen::Matrix4d black_pose_ = Eigen::Matrix4d::Identity();  // the target's when black_ was taken
  std::map<int, engine::ReflectanceMap> maps_;
  std::filesystem::path save_dir_;
  std::map<int, std::string> surfaces_;  // each learnt target's surface: line, as saved
  // Handed to the render thread.
  std::mutex mutex_;
  std::vector<Learnt> learnt_;
};

}  // namespace projbot::live
