#pragma once
// Moving content on the targets (issue 44): one video player per target with `content:`, sampled at the
// content time of each frame's display time and streamed into the target's material. Every target's content
// runs on the display clock of the frame being drawn, so targets lit in one frame stay in step and a
// dropped frame skips content rather than slowing it. Render thread only (the players decode on their own
// threads).

#include <cstddef>
#include <memory>
#include <string>
#include <vector>

#include "projbot/assets/model.hpp"
#include "projbot/assets/video.hpp"
#include "projbot/config/scene.hpp"
#include "projbot/engine/renderer.hpp"

namespace projbot::engine {

/// The material of `model` that a target's `content.material` names: a material's name or its index; empty:
/// the first textured material (0 where none is). Throws assets::AssetError naming the model and what it has.
int content_material(const assets::Model& model, const std::string& spec);

class SceneContent {
 public:
  /// Opens every target's video and makes it its material's base colour (`model_ids[i]`: target i's model
  /// in `renderer`, `models[i]` its CPU copy). Throws assets::AssetError naming the file or the material.
  SceneContent(Renderer& renderer, const config::Scene& scene, const std::vector<assets::Model>& models,
               const std::vector<std::size_t>& model_ids);
  bool empty() const { return players_.empty(); }
  bool has(int target) const;        ///< target `target` has content (a video, a timeline or both)
  bool has_video(int target) const;  ///< target `target` plays a video

  /// When target `target`'s content time is 0, on the display clock: the tour's start, the arrival at its stop
  /// (`arrival_s`, the stop's start), or at_s after the tour's start.
  double start_s(int target, double tour_start_s, double arrival_s) const;

  struct Sample {
    double content_s = 0.0;  ///< the content time asked for
    double pts_s = 0.0;      ///< the presentation time of the frame shown (NaN: none decoded yet)
    bool fresh = false;      ///< a new frame went to the renderer
  };
  /// Target `target`'s content at `content_s` seconds after its start: a frame not shown before is streamed
  /// to the renderer for the next draw. A target without content gives NaN pts.
  Sample show(int target, double content_s);

  /// Target `target`'s animated material at `content_s`: its timeline's base colour factor (linear between
  /// keys, held outside them, repeating every last key's time where it loops) set on `item`. A target
  /// without a timeline leaves `item` as it is.
  void animate(int target, double content_s, DrawItem& item) const;

  /// Target `target`'s player (it must have a video; targets with the same video and start share one).
  const assets::VideoPlayer& player(int target) const;
  /// Playback errors not reported before, one line each naming the file.
  std::vector<std::string> take_errors();

 private:
  struct Stream {
    int target = -1;
    config::TargetContent spec;
    std::shared_ptr<assets::VideoPlayer> player;  ///< shared by targets with the same video and start
    std::size_t texture = 0;
    int material = 0;
  };
  const Stream* find(int target) const;
  Renderer& renderer_;
  std::vector<Stream> players_;
};

}  // namespace projbot::engine
