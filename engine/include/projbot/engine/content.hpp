#pragma once
// Moving content on the targets (issue 44): one video player per target with `content:`, sampled at the
// content time of each frame's display time and streamed into the target's material. Every target's content
// runs on the display clock of the frame being drawn, so targets lit in one frame stay in step and a
// dropped frame skips content rather than slowing it. Render thread only (the players decode on their own
// threads). Also what a scene's targets are uploaded with: their models and their surfaces.

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <future>
#include <map>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "projbot/assets/model.hpp"
#include "projbot/assets/video.hpp"
#include "projbot/config/scene.hpp"
#include "projbot/engine/photometry.hpp"
#include "projbot/engine/renderer.hpp"

namespace projbot::engine {

/// Loads, scales and recentres each target's model and uploads it: one DrawItem per target, at its
/// T_projector_target (and the models into `models` when given, in the same order). Throws
/// assets::AssetError naming a model that cannot be read.
std::vector<DrawItem> upload_scene(Renderer& renderer, const config::Scene& scene, std::vector<assets::Model>* models = nullptr);

/// A target's `surface.texture` read for its model (loaded as upload_scene loads it); null when the
/// surface is one colour. Throws assets::AssetError naming the file when it cannot be read, or when the
/// model has no texture coordinates to lay it on.
std::shared_ptr<const assets::Image> load_surface_texture(const config::TargetConfig& target, const assets::Model& model);

/// Each target's surface for compensation (issue 43): its albedo, or its surface texture (albedo 1),
/// bound to its uploaded model (Renderer::set_surface). `models` and `items` as upload_scene gives them.
/// Throws as load_surface_texture.
std::vector<CompensationPlan::Target> upload_surfaces(Renderer& renderer, const config::Scene& scene,
                                                      const std::vector<assets::Model>& models,
                                                      const std::vector<DrawItem>& items);

/// The material of `model` that a target's `content.material` names: a material's name or its index; empty:
/// the first textured material (0 where none is). Throws assets::AssetError naming the model and what it has.
int content_material(const assets::Model& model, const std::string& spec);

class SceneContent {
 public:
  /// Opens every target's video and makes it its material's base colour, and keeps its model's material
  /// animations (`items[i]`: target i's uploaded
  /// model, as upload_scene gives them; `models[i]` its CPU copy). Throws assets::AssetError naming the file
  /// or the material.
  SceneContent(Renderer& renderer, const config::Scene& scene, const std::vector<assets::Model>& models,
               const std::vector<DrawItem>& items);
  bool empty() const { return players_.empty(); }
  /// Exact: show() waits for the decoder until the frame due is decoded (a replay: the same frames every
  /// time); otherwise (live) it never waits, and a late decoder repeats the frame shown.
  void set_exact(bool exact) { exact_ = exact; }
  bool has(int target) const;        ///< target `target` has content (a video, a timeline, its model's animations)
  bool has_video(int target) const;  ///< target `target` plays a video

  /// When target `target`'s content time is 0, on the display clock: the tour's start, the arrival at its stop
  /// (`arrival_s`, the stop's start), or at_s after the tour's start.
  double start_s(int target, double tour_start_s, double arrival_s) const;

  struct Sample {
    double content_s = 0.0;  ///< the video's own time asked for (content time since it began, or since a swap)
    double pts_s = 0.0;      ///< the presentation time of the frame shown (NaN: none decoded yet)
    bool fresh = false;      ///< a new frame went to the renderer
  };
  /// Target `target`'s content at `content_s` seconds after its start: a frame not shown before is streamed
  /// to the renderer for the next draw. A target without content gives NaN pts.
  Sample show(int target, double content_s);

  /// Both of the below for a target drawn with `item` at `content_s`: its video's frame (show) and its
  /// timeline (animate).
  Sample apply(int target, double content_s, DrawItem& item);

  /// Target `target`'s animated materials at `content_s`, set on `item` (DrawItem::materials): the model's own
  /// material animations (glTF KHR_animation_pointer, each repeating over its length), then its timeline's
  /// properties on its content material (linear between keys, held outside them, repeating every last key's
  /// time where it loops). A target with neither leaves `item` as it is.
  void animate(int target, double content_s, DrawItem& item) const;

  /// Watches the content files while it runs: at most every `interval_s` (on `now_s`'s clock) it looks at
  /// each video's size and modification time; a changed one is opened again on a loader thread, and a later
  /// call swaps it in (the texture kept where the size is the same) from content time 0 of its own; a file
  /// that fails to load leaves the old one playing. Each target's model files (Model::files: the model, a
  /// glTF's buffers and textures) likewise: a changed one is loaded again and its textures, materials and
  /// their animations are drawn from then on, where its shape is the same (the trackers keep the shape
  /// they were given: a new one needs a restart) and its materials as many. Call once per frame on the
  /// render thread. Returns one line per swap or failure, naming the file.
  std::vector<std::string> reload_changed(double now_s, double interval_s = 0.5);

  /// Target `target`'s video replaced by `file` (the operator's console, issue 70): opened on a loader
  /// thread; a later reload_changed swaps it in for this target alone (targets that shared its video go on
  /// with it), playing from its own start, and says so; a file that does not open is said there, and the
  /// old video goes on. Throws EngineError for a target that plays no video.
  void switch_video(int target, const std::filesystem::path& file);

  /// Target `target`'s player (it must have a video; targets with the same video and start share one).
  const assets::VideoPlayer& player(int target) const;
  /// The videos played, each once (targets with the same video and start share one).
  std::vector<const assets::VideoPlayer*> videos() const;
  /// Each video's playback so far, for people: frames shown, skipped, repeated, loops, waits ("" without video).
  std::string summary() const;
  /// Playback errors not reported before, one line each naming the file.
  std::vector<std::string> take_errors();

 private:
  struct Stream {
    int target = -1;
    config::TargetContent spec;
    std::shared_ptr<assets::VideoPlayer> player;  ///< shared by targets with the same video and start
    std::size_t texture = 0;
    int material = 0;
    std::size_t model = 0;  ///< its model in the renderer
    /// The model's materials as loaded and their animations (no geometry): what animate() starts from.
    std::shared_ptr<assets::Model> materials;
    double offset_s = 0.0;  ///< content time when its video was swapped in (it plays from its own start)
    double last_s = 0.0;    ///< the content time last shown
  };
  // A file as it was when last looked at.
  struct FileStamp {
    std::filesystem::path file;
    std::filesystem::file_time_type written{};
    std::uintmax_t size = 0;
    bool changed();  // since the last look (which it becomes); false while it cannot be read
  };
  // A video as played (one per player) and its file as it was when loaded, and its reload under way.
  struct Watch {
    std::shared_ptr<assets::VideoPlayer> player;
    FileStamp stamp;
    std::future<std::unique_ptr<assets::VideoDecoder>> loading;
  };
  // A target's model as drawn: where it came from, its files, its shape, and its reload under way.
  struct ModelWatch {
    int target = -1;
    std::size_t model = 0;  // in the renderer
    std::filesystem::path path;
    double scale = 1.0;
    bool recenter = false;
    std::vector<FileStamp> files;
    std::uint64_t shape = 0;  // shape_of its model
    std::future<assets::Model> loading;
  };
  // A video the operator asked a target to play, while it opens.
  struct Switch {
    int target = -1;
    std::filesystem::path file;
    std::future<std::unique_ptr<assets::VideoDecoder>> loading;
  };
  static std::uint64_t shape_of(const assets::Model& model);
  void take_switches(std::vector<std::string>& said);
  std::string switch_in(const Switch& sw, std::unique_ptr<assets::VideoDecoder> decoder);
  std::size_t texture_for(const Stream& s, int width, int height);
  void release(const std::shared_ptr<assets::VideoPlayer>& player, std::size_t texture);
  void watch_models(const config::Scene& scene, const std::vector<assets::Model>& models, const std::vector<DrawItem>& items);
  void reload_videos(bool due, std::vector<std::string>& said);
  void reload_models(bool due, std::vector<std::string>& said);
  std::string swap_model(ModelWatch& w, assets::Model fresh);
  const Stream* find(int target) const;
  Stream* find(int target) { return const_cast<Stream*>(std::as_const(*this).find(target)); }
  std::shared_ptr<assets::VideoPlayer> make_player(std::unique_ptr<assets::VideoDecoder> decoder, bool loop);
  void swap_in(Watch& w, std::unique_ptr<assets::VideoDecoder> decoder);
  Renderer& renderer_;
  std::vector<Stream> players_;
  std::vector<Watch> watches_;             // one per player
  std::vector<ModelWatch> model_watches_;  // one per target
  std::vector<Switch> switches_;
  std::map<std::pair<int, int>, std::vector<std::size_t>> spare_textures_;  // no stream draws them; by width, height
  std::vector<std::string> names_;                                          // the targets', by index
  double last_look_s_ = -1e300;
  bool exact_ = false;
};

}  // namespace projbot::engine
