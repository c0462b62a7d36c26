// The scene's moving content: players per target, bound to materials, sampled on the display clock.
#include "projbot/engine/content.hpp"

#include <algorithm>
#include <charconv>
#include <chrono>
#include <cmath>
#include <numbers>
#include <optional>

#include "projbot/assets/image.hpp"
#include "projbot/config/angles.hpp"

namespace projbot::engine {

std::shared_ptr<const assets::Image> load_surface_texture(const config::TargetConfig& target, const assets::Model& model) {
  if (target.surface.texture.empty()) return nullptr;
  if (!assets::has_texture_coordinates(model))
    throw assets::AssetError(target.surface.texture.string() + ": target '" + target.name + "'s surface texture needs texture " +
                             "coordinates, and its model " + target.model.string() + " has none");
  return std::make_shared<const assets::Image>(assets::read_image(target.surface.texture));
}

std::vector<CompensationPlan::Target> upload_surfaces(Renderer& renderer, const config::Scene& scene,
                                                      const std::vector<assets::Model>& models,
                                                      const std::vector<DrawItem>& items) {
  std::vector<CompensationPlan::Target> out;
  for (std::size_t i = 0; i < models.size() && i < items.size() && i < scene.targets.size(); ++i) {
    CompensationPlan::Target t{&models[i], scene.targets[i].surface.albedo, load_surface_texture(scene.targets[i], models[i])};
    if (t.surface) renderer.set_surface(items[i].model, *t.surface);
    out.push_back(std::move(t));
  }
  return out;
}

int content_material(const assets::Model& model, const std::string& spec) {
  const auto n = static_cast<int>(model.materials.size());
  if (spec.empty()) {
    for (int i = 0; i < n; ++i)
      if (model.materials[static_cast<std::size_t>(i)].base_color_image >= 0) return i;
    return 0;
  }
  for (int i = 0; i < n; ++i)
    if (model.materials[static_cast<std::size_t>(i)].name == spec) return i;
  int index = -1;
  const auto [end, ec] = std::from_chars(spec.data(), spec.data() + spec.size(), index);
  if (ec == std::errc() && end == spec.data() + spec.size() && index >= 0 && index < n) return index;
  std::string names;
  for (int i = 0; i < n; ++i) {
    const std::string& name = model.materials[static_cast<std::size_t>(i)].name;
    names += (i > 0 ? ", " : "") + std::to_string(i) + (name.empty() ? " (unnamed)" : " '" + name + "'");
  }
  throw assets::AssetError(model.source + ": no material '" + spec + "' for the content (its " + std::to_string(n) +
                           (n == 1 ? " material: " : " materials: ") + names + ")");
}

namespace {

// A file's modification time and size (both unchanged: the file is as it was); false where it cannot be read.
bool file_stamp(const std::filesystem::path& file, std::filesystem::file_time_type& written, std::uintmax_t& size) {
  std::error_code ec1, ec2;
  written = std::filesystem::last_write_time(file, ec1);
  size = std::filesystem::file_size(file, ec2);
  return !ec1 && !ec2;
}

// Whether a reload under way has finished (its result or its failure waits in it).
template <typename T>
bool loaded(const std::future<T>& loading) {
  return loading.valid() && loading.wait_for(std::chrono::seconds(0)) == std::future_status::ready;
}

}  // namespace

std::vector<DrawItem> upload_scene(Renderer& renderer, const config::Scene& scene, std::vector<assets::Model>* models) {
  std::vector<DrawItem> items;
  for (const auto& target : scene.targets) {
    auto model = assets::load_model(target.model);
    assets::scale_and_recenter(model, target.scale, target.recenter);
    items.push_back({renderer.add_model(model), target.T_projector_target});
    if (models) models->push_back(std::move(model));
  }
  return items;
}

namespace {

// Each stream of its own is a decoder thread (and FFmpeg's) with its frames queued and a texture: 300 of
// them ended in "Resource temporarily unavailable", no thread left and no limit named.
constexpr std::size_t kMaxStreams = 64;

// Targets showing the same video from the same start share one player (decoded and uploaded once).
bool same_stream(const config::TargetContent& a, const config::TargetContent& b) {
  return a.video == b.video && a.loop == b.loop && a.start == b.start && a.at_s == b.at_s;
}

void check_stream_count(const config::Scene& scene) {
  std::vector<const config::TargetContent*> streams;
  for (const auto& t : scene.targets)
    if (t.content && !t.content->video.empty() &&
        std::none_of(streams.begin(), streams.end(), [&](const auto* o) { return same_stream(*o, *t.content); }))
      streams.push_back(&*t.content);
  if (streams.size() > kMaxStreams)
    throw assets::AssetError(scene.source.string() + ": " + std::to_string(streams.size()) +
                             " videos would play at once, each with its own decoder; at most " + std::to_string(kMaxStreams) +
                             " do (targets with the same video, loop and start share one)");
}

}  // namespace

std::shared_ptr<assets::VideoPlayer> SceneContent::make_player(std::unique_ptr<assets::VideoDecoder> decoder, bool loop) {
  return std::make_shared<assets::VideoPlayer>(std::move(decoder), loop, 4,
                                               [this](std::size_t bytes) { return renderer_.frame_memory(bytes); });
}

SceneContent::SceneContent(Renderer& renderer, const config::Scene& scene, const std::vector<assets::Model>& models,
                           const std::vector<DrawItem>& items)
    : renderer_(renderer) {
  check_stream_count(scene);
  for (std::size_t i = 0; i < scene.targets.size() && i < models.size() && i < items.size(); ++i) {
    const auto& content = scene.targets[i].content;
    if (!content && models[i].material_animations.empty()) continue;
    Stream s;
    s.target = static_cast<int>(i);
    s.spec = content.value_or(config::TargetContent{});
    const int material = content_material(models[i], s.spec.material);
    // A model without texture coordinates would take one pixel of the video everywhere: never the picture.
    if (!s.spec.video.empty() && !assets::has_texture_coordinates(models[i]))
      throw assets::AssetError(s.spec.video.string() + ": target '" + scene.targets[i].name +
                               "'s video needs texture coordinates to lie on, and its model " + scene.targets[i].model.string() +
                               " has none");
    s.material = material;
    s.model = items[i].model;
    s.materials = std::make_shared<assets::Model>();
    s.materials->materials = models[i].materials;
    s.materials->material_animations = models[i].material_animations;
    if (s.spec.video.empty()) {  // a timeline, or the model's own animations, alone
      players_.push_back(std::move(s));
      continue;
    }
    // The same video from the same start on several targets: one player and one texture (decoded and
    // uploaded once, and in step by construction).
    const auto same =
        std::find_if(players_.begin(), players_.end(), [&](const Stream& o) { return o.player && same_stream(o.spec, s.spec); });
    if (same != players_.end()) {
      s.player = same->player;
      s.texture = same->texture;
      renderer.bind_streamed_texture(s.texture, s.model, material);
    } else {
      s.player = make_player(std::make_unique<assets::VideoDecoder>(s.spec.video), s.spec.loop);
      s.texture = renderer.add_streamed_texture(s.model, material, s.player->info().width, s.player->info().height);
      Watch w;
      w.player = s.player;
      w.stamp.file = s.spec.video;
      w.stamp.changed();
      watches_.push_back(std::move(w));
    }
    players_.push_back(std::move(s));
  }
  watch_models(scene, models, items);
  for (const config::TargetConfig& t : scene.targets) names_.push_back(t.name);
}

const SceneContent::Stream* SceneContent::find(int target) const {
  for (const Stream& s : players_)
    if (s.target == target) return &s;
  return nullptr;
}

bool SceneContent::has(int target) const { return find(target) != nullptr; }
bool SceneContent::has_video(int target) const {
  const Stream* s = find(target);
  return s != nullptr && s->player != nullptr;
}

namespace {

// Material `material`'s state in `item`: the one set there, else as loaded (added to the item).
assets::MaterialState& look(DrawItem& item, const assets::Model& materials, int material) {
  for (auto& [m, state] : item.materials)
    if (m == material) return state;
  item.materials.emplace_back(material, materials.materials[static_cast<std::size_t>(material)].state());
  return item.materials.back().second;
}

// `a` and `b` (the same properties given) mixed w of the way to b, over `state`.
void mix_keys(const config::TargetContent::Key& a, const config::TargetContent::Key& b, double w, assets::MaterialState& state) {
  const auto mix = [w](double x, double y) { return x + w * (y - x); };
  if (a.base_color_factor && b.base_color_factor)
    for (std::size_t c = 0; c < 4; ++c)
      state.base_color_factor[c] = static_cast<float>(mix((*a.base_color_factor)[c], (*b.base_color_factor)[c]));
  if (a.emissive_factor && b.emissive_factor)
    for (std::size_t c = 0; c < 3; ++c)
      state.emissive_factor[c] = static_cast<float>(mix((*a.emissive_factor)[c], (*b.emissive_factor)[c]));
  auto& t = state.base_color_transform;
  for (std::size_t c = 0; c < 2; ++c) {
    if (a.uv_offset && b.uv_offset) t.offset[c] = mix((*a.uv_offset)[c], (*b.uv_offset)[c]);
    if (a.uv_scale && b.uv_scale) t.scale[c] = mix((*a.uv_scale)[c], (*b.uv_scale)[c]);
  }
  if (a.uv_rotation_deg && b.uv_rotation_deg) t.rotation_rad = config::radians(mix(*a.uv_rotation_deg, *b.uv_rotation_deg));
}

}  // namespace

void SceneContent::animate(int target, double content_s, DrawItem& item) const {
  const Stream* s = find(target);
  if (s == nullptr) return;
  for (const auto& [material, state] : assets::animate_materials(*s->materials, content_s))
    look(item, *s->materials, material) = state;
  const auto& keys = s->spec.timeline;
  if (keys.empty()) return;
  double t = std::max(0.0, content_s);
  const double period = keys.back().at_s;
  if (s->spec.loop && period > 0.0) t = std::fmod(t, period);
  std::size_t k = 0;
  while (k + 1 < keys.size() && keys[k + 1].at_s <= t) ++k;
  const auto& a = keys[k];
  const auto& b = keys[std::min(k + 1, keys.size() - 1)];
  const double w = b.at_s > a.at_s ? std::clamp((t - a.at_s) / (b.at_s - a.at_s), 0.0, 1.0) : 0.0;
  mix_keys(a, b, w, look(item, *s->materials, s->material));
}

double SceneContent::start_s(int target, double tour_start_s, double arrival_s) const {
  const Stream* s = find(target);
  if (s == nullptr) return tour_start_s;
  switch (s->spec.start) {
    case config::TargetContent::Start::kArrival:
      return arrival_s;
    case config::TargetContent::Start::kAt:
      return tour_start_s + s->spec.at_s;
    default:
      return tour_start_s;
  }
}

SceneContent::Sample SceneContent::show(int target, double content_s) {
  Sample out;
  out.content_s = content_s;
  out.pts_s = std::nan("");
  Stream* s = find(target);
  if (s == nullptr || !s->player) return out;
  if (content_s < s->offset_s) s->offset_s = 0.0;  // the content began again (an arrival): so does a swapped-in video
  s->last_s = content_s;
  // Before its start the content waits on its first frame.
  out.content_s = std::max(0.0, content_s - s->offset_s);
  const assets::VideoPlayer::Shown shown = exact_ ? s->player->frame_due(out.content_s) : s->player->frame_at(out.content_s);
  if (!shown.frame) return out;
  out.pts_s = shown.frame->pts_s;
  out.fresh = shown.fresh;
  if (!shown.fresh) return out;
  if (shown.frame->pixels.data != nullptr)  // decoded into the renderer's frame memory: no copy here
    renderer_.stream_pixels(s->texture, shown.frame->pixels, shown.frame);
  else
    renderer_.stream_frame(s->texture, std::shared_ptr<const assets::Image>(shown.frame, &shown.frame->image));
  return out;
}

SceneContent::Sample SceneContent::apply(int target, double content_s, DrawItem& item) {
  animate(target, content_s, item);
  return show(target, content_s);
}

std::vector<std::string> SceneContent::reload_changed(double now_s, double interval_s) {
  std::vector<std::string> said;
  const bool due = now_s - last_look_s_ >= interval_s;  // the files looked at again
  if (due) last_look_s_ = now_s;
  reload_videos(due, said);
  reload_models(due, said);
  take_switches(said);
  return said;
}

void SceneContent::switch_video(int target, const std::filesystem::path& file) {
  const Stream* s = find(target);
  if (s == nullptr || !s->player) throw EngineError("target " + std::to_string(target) + " plays no video to switch");
  switches_.push_back(
      {target, file, std::async(std::launch::async, [file] { return std::make_unique<assets::VideoDecoder>(file); })});
}

// The switches whose video has opened, in the order asked.
void SceneContent::take_switches(std::vector<std::string>& said) {
  while (!switches_.empty() && loaded(switches_.front().loading)) {
    const Switch& sw = switches_.front();
    try {
      said.push_back(switch_in(sw, switches_.front().loading.get()));
    } catch (const std::exception& e) {
      said.push_back(std::string(e.what()) + " (asked for on '" + names_.at(static_cast<std::size_t>(sw.target)) +
                     "'; its old video goes on)");
    }
    switches_.erase(switches_.begin());
  }
}

// The target's stream given the new player (from content time now, as a changed file is), a texture of its
// size, and a watch on its file; the old player and texture let go where no other target plays them.
std::string SceneContent::switch_in(const Switch& sw, std::unique_ptr<assets::VideoDecoder> decoder) {
  Stream& s = *find(sw.target);
  auto fresh = make_player(std::move(decoder), s.spec.loop);
  const std::shared_ptr<assets::VideoPlayer> old = s.player;
  const std::size_t old_texture = s.texture;
  s.texture = texture_for(s, fresh->info().width, fresh->info().height);
  s.player = fresh;
  s.offset_s = s.last_s;
  s.spec.video = sw.file;
  Watch w;
  w.player = fresh;
  w.stamp.file = sw.file;
  w.stamp.changed();
  watches_.push_back(std::move(w));
  release(old, old_texture);
  return sw.file.string() + ": now plays on '" + names_.at(static_cast<std::size_t>(sw.target)) + "', from its start";
}

// A texture no stream draws, of this size, or a new one: switching back and forth adds none.
std::size_t SceneContent::texture_for(const Stream& s, int width, int height) {
  std::vector<std::size_t>& spare = spare_textures_[{width, height}];
  if (spare.empty()) return renderer_.add_streamed_texture(s.model, s.material, width, height);
  const std::size_t texture = spare.back();
  spare.pop_back();
  renderer_.bind_streamed_texture(texture, s.model, s.material);
  return texture;
}

void SceneContent::release(const std::shared_ptr<assets::VideoPlayer>& player, std::size_t texture) {
  const auto plays = [&](const Stream& s) { return s.player == player; };
  if (std::none_of(players_.begin(), players_.end(), plays))
    std::erase_if(watches_, [&](const Watch& w) { return w.player == player; });
  if (std::none_of(players_.begin(), players_.end(), [&](const Stream& s) { return s.player && s.texture == texture; }))
    spare_textures_[{player->info().width, player->info().height}].push_back(texture);
}

void SceneContent::reload_videos(bool due, std::vector<std::string>& said) {
  for (Watch& w : watches_) {  // loads that have finished
    if (!loaded(w.loading)) continue;
    try {
      swap_in(w, w.loading.get());
      said.push_back(w.stamp.file.string() + ": changed; the new video plays from its start");
    } catch (const std::exception& e) {
      said.push_back(std::string(e.what()) + " (changed on disk; the old video goes on)");
    }
  }
  if (!due) return;
  for (Watch& w : watches_) {
    if (w.loading.valid() || !w.stamp.changed()) continue;  // loading, gone for now, or as it was
    w.loading = std::async(std::launch::async, [file = w.stamp.file] { return std::make_unique<assets::VideoDecoder>(file); });
  }
}

bool SceneContent::FileStamp::changed() {
  std::filesystem::file_time_type now_written;
  std::uintmax_t now_size = 0;
  if (!file_stamp(file, now_written, now_size) || (now_written == written && now_size == size)) return false;
  written = now_written;
  size = now_size;
  return true;
}

std::uint64_t SceneContent::shape_of(const assets::Model& model) {
  std::uint64_t h = 1469598103934665603ULL;  // FNV-1a over the positions' and indices' bytes
  const auto mix = [&h](const void* data, std::size_t n) {
    for (std::size_t i = 0; i < n; ++i) h = (h ^ static_cast<const std::uint8_t*>(data)[i]) * 1099511628211ULL;
  };
  for (const assets::Primitive& p : model.primitives) {
    for (const assets::Vertex& v : p.vertices) mix(v.position.data(), sizeof v.position);
    mix(p.indices.data(), p.indices.size() * sizeof(std::uint32_t));
  }
  return h;
}

void SceneContent::watch_models(const config::Scene& scene, const std::vector<assets::Model>& models,
                                const std::vector<DrawItem>& items) {
  for (std::size_t i = 0; i < scene.targets.size() && i < models.size() && i < items.size(); ++i) {
    ModelWatch w;
    w.target = static_cast<int>(i);
    w.model = items[i].model;
    w.path = scene.targets[i].model;
    w.scale = scene.targets[i].scale;
    w.recenter = scene.targets[i].recenter;
    for (const auto& f : models[i].files) {
      FileStamp st{f};
      st.changed();
      w.files.push_back(std::move(st));
    }
    w.shape = shape_of(models[i]);
    model_watches_.push_back(std::move(w));
  }
}

void SceneContent::reload_models(bool due, std::vector<std::string>& said) {
  for (ModelWatch& w : model_watches_) {  // loads that have finished
    if (!loaded(w.loading)) continue;
    try {
      said.push_back(swap_model(w, w.loading.get()));
    } catch (const std::exception& e) {
      said.push_back(std::string(e.what()) + " (changed on disk; the model as it was stays)");
    }
  }
  if (!due) return;
  for (ModelWatch& w : model_watches_) {
    if (w.loading.valid()) continue;
    bool changed = false;
    for (FileStamp& f : w.files) changed = f.changed() || changed;  // every stamp brought up to date
    if (!changed) continue;
    w.loading = std::async(std::launch::async, [path = w.path, scale = w.scale, recenter = w.recenter] {
      assets::Model m = assets::load_model(path);
      assets::scale_and_recenter(m, scale, recenter);
      return m;
    });
  }
}

std::string SceneContent::swap_model(ModelWatch& w, assets::Model fresh) {
  const std::string name = w.path.string();
  if (shape_of(fresh) != w.shape)
    return name + ": changed shape; the trackers keep the shape they were given, so it is not drawn (restart to use it)";
  renderer_.replace_model(w.model, fresh);  // throws, keeping the old, where its materials differ in number
  Stream* s = find(w.target);
  if (s == nullptr && !fresh.material_animations.empty()) {  // animated now: played from here on
    Stream animated;
    animated.target = w.target;
    animated.model = w.model;
    animated.material = content_material(fresh, "");
    animated.materials = std::make_shared<assets::Model>();
    players_.push_back(std::move(animated));
    s = &players_.back();
  }
  if (s != nullptr) {
    s->materials->materials = fresh.materials;
    s->materials->material_animations = fresh.material_animations;
  }
  return name + ": changed; its textures and materials are drawn from now on";
}

void SceneContent::swap_in(Watch& w, std::unique_ptr<assets::VideoDecoder> decoder) {
  const bool loop =
      std::find_if(players_.begin(), players_.end(), [&](const Stream& s) { return s.player == w.player; })->spec.loop;
  auto fresh = make_player(std::move(decoder), loop);
  const bool same_size = fresh->info().width == w.player->info().width && fresh->info().height == w.player->info().height;
  std::optional<std::size_t> texture;
  for (Stream& s : players_) {
    if (s.player != w.player) continue;
    if (!same_size) {  // a new texture of the new size, bound to every material the old one was
      if (!texture)
        texture = renderer_.add_streamed_texture(s.model, s.material, fresh->info().width, fresh->info().height);
      else
        renderer_.bind_streamed_texture(*texture, s.model, s.material);
      s.texture = *texture;
    }
    s.player = fresh;
    s.offset_s = s.last_s;
  }
  w.player = fresh;
}

const assets::VideoPlayer& SceneContent::player(int target) const {
  const Stream* s = find(target);
  if (s == nullptr || !s->player) throw EngineError("target " + std::to_string(target) + " plays no video");
  return *s->player;
}

std::vector<const assets::VideoPlayer*> SceneContent::videos() const {
  std::vector<const assets::VideoPlayer*> out;
  for (const Watch& w : watches_) out.push_back(w.player.get());
  return out;
}

std::string SceneContent::summary() const {
  std::string out;
  for (const assets::VideoPlayer* p : videos()) {
    const assets::PlaybackStats st = p->stats();
    out += (out.empty() ? "" : "; ") + p->name() + ": " + std::to_string(st.shown) + " video frames shown, " +
           std::to_string(st.skipped) + " skipped, " + std::to_string(st.repeated) + " repeated, " + std::to_string(st.loops) +
           " loops, " + std::to_string(st.seeks) + " jumps ahead, the renderer waited on its decoder " +
           std::to_string(st.waits) + " times";
  }
  return out;
}

std::vector<std::string> SceneContent::take_errors() {
  std::vector<std::string> out;
  for (Watch& w : watches_)
    if (std::string e = w.player->take_error(); !e.empty()) out.push_back(e);
  return out;
}

}  // namespace projbot::engine
