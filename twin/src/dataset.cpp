#include "projbot/twin/dataset.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iomanip>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <random>
#include <sstream>

#include "projbot/alignment/bop.hpp"
#include "projbot/assets/image.hpp"
#include "projbot/assets/model.hpp"
#include "projbot/config/angles.hpp"
#include "projbot/config/lens.hpp"
#include "projbot/config/output_file.hpp"
#include "projbot/twin/shapes.hpp"
#include "projbot/twin/spectator.hpp"
#include "projbot/twin/world.hpp"

namespace projbot::twin {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

constexpr int kFirstProceduralId = 101;
constexpr double kContactM = 0.003;       // vertices this near the table carry the object
constexpr double kStableMarginM = 0.003;  // its centre lies this far inside what carries it
constexpr double kSameSurfaceM = 0.001;   // an instance's pixel is visible where it is the nearest surface
constexpr double kDepthUnitMm = 0.1;      // depth PNGs in 0.1 mm, as the real frames' are
// What the table in front of the shelf can hold (0.70 x 0.58 m, the first object within 4 cm of its middle)
// and what the camera, 0.6-1.5 m away, sees as more than a few pixels: an object's largest side.
constexpr double kMinSideMm = 10.0, kMaxSideMm = 500.0;

// A way an object rests on the table: the rotation that takes its model frame there (before its turn
// about the vertical) and how likely it is (the area of the face it stands on).
struct Rest {
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
  double weight = 1.0;
};

struct Object {
  int id = 0;
  assets::Model model;                  // metres, the dataset's own model frame
  std::vector<Eigen::Vector3d> points;  // its vertices, read once: placing an object tries up to 200 poses
  fs::path source;                      // the PLY copied; empty for a procedural shape, written from `model`
  double diameter_mm = 0.0;
  json symmetries;  // BOP's symmetry entries, or null
  std::vector<Rest> rests;
  std::size_t depth_id = 0, colour_id = 0;  // renderer models
};

std::vector<Eigen::Vector3d> vertices(const assets::Model& m) {
  std::vector<Eigen::Vector3d> out;
  for (const auto& p : m.primitives)
    for (const auto& v : p.vertices) out.emplace_back(v.position[0], v.position[1], v.position[2]);
  return out;
}

double cross2(const Eigen::Vector2d& o, const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  return (a - o).x() * (b - o).y() - (a - o).y() * (b - o).x();
}

// Andrew's monotone chain: the convex hull, counter-clockwise.
std::vector<Eigen::Vector2d> convex_hull(std::vector<Eigen::Vector2d> p) {
  std::sort(p.begin(), p.end(), [](const auto& a, const auto& b) { return a.x() < b.x() || (a.x() == b.x() && a.y() < b.y()); });
  if (p.size() < 3) return p;
  std::vector<Eigen::Vector2d> h(2 * p.size());
  std::size_t k = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    while (k >= 2 && cross2(h[k - 2], h[k - 1], p[i]) <= 0) --k;
    h[k++] = p[i];
  }
  for (std::size_t i = p.size() - 1, t = k + 1; i-- > 0;) {
    while (k >= t && cross2(h[k - 2], h[k - 1], p[i]) <= 0) --k;
    h[k++] = p[i];
  }
  h.resize(k - 1);
  return h;
}

// Whether `c` lies inside the counter-clockwise hull by at least `margin`.
bool inside(const std::vector<Eigen::Vector2d>& hull, const Eigen::Vector2d& c, double margin) {
  if (hull.size() < 3) return false;
  for (std::size_t i = 0; i < hull.size(); ++i) {
    const Eigen::Vector2d a = hull[i], b = hull[(i + 1) % hull.size()];
    if (cross2(a, b, c) / (b - a).norm() < margin) return false;
  }
  return true;
}

// The rotation whose third row is -down (world up) and first the model axis `across`.
Eigen::Matrix3d standing_on(const Eigen::Vector3d& down, const Eigen::Vector3d& across) {
  Eigen::Matrix3d R;
  R.row(2) = -down.transpose();
  R.row(0) = across.transpose();
  R.row(1) = R.row(2).cross(R.row(0));
  return R;
}

// Its stable rests on the faces of its bounding box: standing on a face, the vertices within kContactM of
// it carry it, and its surface centroid must lie over what they span (a bowl on its rim or its foot, not
// on its side; a cylinder on its side or its end). None stable (a sphere): all six.
std::vector<Rest> resting_orientations(const assets::Model& m, const std::vector<Eigen::Vector3d>& v) {
  const Eigen::Vector3d c = m.surface_centroid(), size = m.bounds().sizes();
  std::vector<Rest> stable, all;
  for (int k = 0; k < 3; ++k)
    for (const double side : {-1.0, 1.0}) {
      const Eigen::Vector3d down = side * Eigen::Vector3d::Unit(k), u = Eigen::Vector3d::Unit((k + 1) % 3),
                            w = Eigen::Vector3d::Unit((k + 2) % 3);
      double lowest = -1e9;
      for (const auto& p : v) lowest = std::max(lowest, p.dot(down));
      std::vector<Eigen::Vector2d> contact;
      for (const auto& p : v)
        if (p.dot(down) > lowest - kContactM) contact.emplace_back(p.dot(u), p.dot(w));
      const Rest rest{standing_on(down, u), size[(k + 1) % 3] * size[(k + 2) % 3]};
      all.push_back(rest);
      if (inside(convex_hull(contact), {c.dot(u), c.dot(w)}, kStableMarginM)) stable.push_back(rest);
    }
  return stable.empty() ? all : stable;
}

double diameter_mm(const std::vector<Eigen::Vector3d>& v) {
  double d2 = 0.0;
  for (std::size_t i = 0; i < v.size(); ++i)
    for (std::size_t j = i + 1; j < v.size(); ++j) d2 = std::max(d2, (v[i] - v[j]).squaredNorm());
  return 1000.0 * std::sqrt(d2);
}

// A symmetric object of a models folder (its own symmetry entries, or YCB-V's list) keeps a flag the
// scoring reads: the half turn about its most distinct principal axis through its middle, the one
// symmetry a can, a marker and a clamp share.
json half_turn(const std::vector<Eigen::Vector3d>& v) {
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const auto& p : v) mean += p;
  mean /= static_cast<double>(v.size());
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (const auto& p : v) cov += (p - mean) * (p - mean).transpose();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(cov);
  const Eigen::Vector3d l = eig.eigenvalues();
  const int k = (l[1] - l[0] > l[2] - l[1]) ? 0 : 2;  // the eigenvalue farther from the other two
  const Eigen::Vector3d a = eig.eigenvectors().col(k);
  const Eigen::Matrix3d R = 2.0 * a * a.transpose() - Eigen::Matrix3d::Identity();
  const Eigen::Vector3d t = 1000.0 * (mean - R * mean);
  json T = json::array();
  for (int r = 0; r < 4; ++r)
    for (int col = 0; col < 4; ++col) T.push_back(r < 3 ? (col < 3 ? R(r, col) : t[r]) : (col < 3 ? 0.0 : 1.0));
  return json::array({T});
}

// Colour as the colour camera sees it: the object's albedo, darker where its surface turns from a light
// fixed to it (the twin's colour is a cue, not a photometric model).
assets::Model coloured(const assets::Model& m, const std::array<float, 3>& albedo) {
  assets::Model out = m;
  const Eigen::Vector3f light = Eigen::Vector3f(0.3F, -0.4F, 0.87F).normalized();
  for (auto& p : out.primitives)
    for (auto& v : p.vertices) {
      const float shade = 0.55F + 0.45F * std::max(0.0F, Eigen::Vector3f(v.normal[0], v.normal[1], v.normal[2]).dot(light));
      v.color = {albedo[0] * shade, albedo[1] * shade, albedo[2] * shade, 1.0F};
    }
  for (auto& mat : out.materials) mat.base_color_factor = {1.0F, 1.0F, 1.0F, 1.0F}, mat.base_color_image = -1;
  return out;
}

std::array<float, 3> albedo_for(int id) {
  std::mt19937 rng(static_cast<std::uint32_t>(id) * 2654435761U);
  std::uniform_real_distribution<float> level(0.15F, 0.95F);
  return {level(rng), level(rng), level(rng)};
}

// Every folder's objects, ids checked across folders before any mesh is loaded; `stopped` asked between
// meshes (seventeen take a second or two): what it stops leaves out the rest.
// An object the table cannot hold, or too small to be seen, would never be placed: said, with its size.
void check_placeable(const assets::Model& model, const fs::path& file) {
  const Eigen::AlignedBox3d box = model.bounds();
  const double side_mm = box.isEmpty() ? 0.0 : 1000.0 * box.sizes().maxCoeff();
  if (!(side_mm >= kMinSideMm && side_mm <= kMaxSideMm)) {
    std::ostringstream what;
    what << file.string() << ": " << std::fixed << std::setprecision(side_mm < 1.0 ? 4 : 1) << side_mm
         << " mm across; the twin's table places objects " << static_cast<int>(kMinSideMm) << ".." << static_cast<int>(kMaxSideMm)
         << " mm across (models in millimetres, as BOP's are)";
    throw alignment::AlignmentError(what.str());
  }
}

// The procedural shapes take `procedural` ids from kFirstProceduralId: a folder's object there (an earlier
// twin dataset's models folder) would be two objects under one id.
std::vector<Object> folder_objects(const std::vector<fs::path>& folders, int procedural, const std::function<bool()>& stopped) {
  std::vector<alignment::BopObject> listed;
  std::map<int, fs::path> seen;
  for (const auto& folder : folders)
    for (const auto& o : alignment::read_bop_models(folder)) {
      if (const auto [at, fresh] = seen.emplace(o.id, folder); !fresh)
        throw alignment::AlignmentError(folder.string() + ": object " + std::to_string(o.id) + " is also in " +
                                        at->second.string() + " (ids must differ across --models folders)");
      if (o.id >= kFirstProceduralId && o.id < kFirstProceduralId + procedural)
        throw alignment::AlignmentError(folder.string() + ": object " + std::to_string(o.id) +
                                        " has an id of the procedural shapes (" + std::to_string(kFirstProceduralId) + ".." +
                                        std::to_string(kFirstProceduralId + procedural - 1) +
                                        "); renumber it, or leave the shapes out with --no-procedural");
      listed.push_back(o);
    }
  std::vector<Object> out;
  for (const auto& o : listed) {
    if (stopped()) break;
    Object obj;
    obj.id = o.id;
    obj.source = o.model;
    obj.model = assets::load_model(o.model);
    assets::scale_and_recenter(obj.model, 0.001, false);
    obj.points = vertices(obj.model);
    check_placeable(obj.model, o.model);
    obj.diameter_mm = 1000.0 * o.diameter_m;
    if (o.symmetric) obj.symmetries = json{{"symmetries_discrete", half_turn(obj.points)}};
    out.push_back(std::move(obj));
  }
  return out;
}

// The objects to place, or none when a stop was asked for while they were loaded.
std::vector<Object> objects_for(const DatasetOptions& options) {
  const auto stopped = [&] { return options.stop_requested && options.stop_requested(); };
  std::vector<ProceduralShape> shapes = options.procedural ? procedural_shapes() : std::vector<ProceduralShape>{};
  std::vector<Object> out = folder_objects(options.model_folders, static_cast<int>(shapes.size()), stopped);
  {
    int id = kFirstProceduralId;
    for (auto& s : shapes) {
      Object obj;
      obj.id = id++;
      obj.model = std::move(s.model);
      obj.points = vertices(obj.model);
      obj.diameter_mm = diameter_mm(obj.points);
      if (s.axis)
        obj.symmetries =
            json{{"symmetries_continuous",
                  json::array({json{{"axis", {s.axis->x(), s.axis->y(), s.axis->z()}}, {"offset", {0.0, 0.0, 0.0}}}})}};
      out.push_back(std::move(obj));
    }
  }
  if (stopped()) return {};
  if (out.empty()) throw alignment::AlignmentError("twin dataset: no objects (no models folder and no procedural shapes)");
  for (auto& o : out) {
    if (stopped()) return {};
    o.rests = resting_orientations(o.model, o.points);
  }
  return stopped() ? std::vector<Object>{} : out;
}

// The models folder: each object's PLY (copied as it came, or written from the procedural mesh) and
// models_info.json with its diameter, bounding box (mm) and symmetries.
void write_models(const fs::path& folder, const std::vector<Object>& objects) {
  fs::create_directories(folder);
  json info = json::object();
  for (const auto& o : objects) {
    char name[32];
    std::snprintf(name, sizeof name, "obj_%06d.ply", o.id);
    if (o.source.empty())
      assets::write_ply(folder / name, o.model, 1000.0);
    else
      config::copy_file(o.source, folder / name);
    const Eigen::AlignedBox3d b = o.model.bounds();
    json entry{{"diameter", o.diameter_mm}};
    const char* axes = "xyz";
    for (int k = 0; k < 3; ++k) {
      entry[std::string("min_") + axes[k]] = 1000.0 * b.min()[k];
      entry[std::string("size_") + axes[k]] = 1000.0 * b.sizes()[k];
    }
    if (!o.symmetries.is_null()) entry.update(o.symmetries);
    info[std::to_string(o.id)] = entry;
  }
  config::write_file_atomically(folder / "models_info.json", info.dump(1));
}

struct Placed {
  const Object* object = nullptr;
  Eigen::Matrix4d T_world_model = Eigen::Matrix4d::Identity();
  Eigen::AlignedBox2d footprint;  // world x-y
};

struct Box {
  Eigen::Vector3d min, max;
  std::array<float, 4> rgba;
};

// The room of a scene: the floor, a table top at z = 0, and behind it a wall, or a shelf on the table
// with a wall farther away.
std::vector<Box> room(std::mt19937& rng) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const auto grey = [&](double lo, double hi) {
    const auto g = static_cast<float>(lo + (hi - lo) * u(rng));
    return std::array<float, 4>{g, g * 0.95F, g * 0.9F, 1.0F};
  };
  std::vector<Box> out{{{-3.0, -3.0, -0.78}, {3.0, 3.0, -0.75}, grey(0.3, 0.5)},
                       {{-0.6, -0.4, -0.03}, {0.6, 0.4, 0.0}, grey(0.35, 0.8)}};
  if (u(rng) < 0.65) {
    const double y = 0.45 + 0.45 * u(rng);
    out.push_back({{-3.0, y, -0.75}, {3.0, y + 0.05, 1.5}, grey(0.5, 0.9)});
  } else {
    const double h = 0.25 + 0.25 * u(rng);
    out.push_back({{-0.5, 0.30, 0.0}, {0.5, 0.40, h}, grey(0.3, 0.7)});
    out.push_back({{-3.0, 1.6, -0.75}, {3.0, 1.65, 1.5}, grey(0.5, 0.9)});
  }
  return out;
}

Eigen::Matrix3d yaw(double a) { return Eigen::AngleAxisd(a, Eigen::Vector3d::UnitZ()).toRotationMatrix(); }

// `o` resting as `rest`, turned by `angle` about the vertical, its footprint's middle at `xy`, on the table.
Placed place(const Object& o, const Rest& rest, double angle, const Eigen::Vector2d& xy) {
  const Eigen::Matrix3d R = yaw(angle) * rest.R;
  Eigen::AlignedBox3d box;
  for (const auto& v : o.points) box.extend(R * v);
  Placed p{&o, Eigen::Matrix4d::Identity(), {}};
  p.T_world_model.topLeftCorner<3, 3>() = R;
  const Eigen::Vector2d middle = box.center().head<2>();
  p.T_world_model.topRightCorner<3, 1>() = Eigen::Vector3d(xy.x() - middle.x(), xy.y() - middle.y(), -box.min().z());
  p.footprint = Eigen::AlignedBox2d(box.min().head<2>() - middle + xy, box.max().head<2>() - middle + xy);
  return p;
}

// Three to six objects, each beside one already placed (touching or nearly: their footprints 2 mm apart
// at the least), on the table in front of the shelf.
std::vector<Placed> arrange(const std::vector<Object>& objects, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<std::size_t> order(objects.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::shuffle(order.begin(), order.end(), rng);
  const auto count = std::min<std::size_t>(order.size(), 3 + rng() % 4);
  const Eigen::AlignedBox2d table(Eigen::Vector2d(-0.35, -0.3), Eigen::Vector2d(0.35, 0.28));
  std::vector<Placed> out;
  for (std::size_t n = 0; n < count; ++n) {
    const Object& o = objects[order[n]];
    std::vector<double> weights;
    for (const auto& r : o.rests) weights.push_back(r.weight);
    std::discrete_distribution<std::size_t> pick(weights.begin(), weights.end());
    for (int attempt = 0; attempt < 200; ++attempt) {
      const Rest& rest = o.rests[pick(rng)];
      Eigen::Vector2d xy(0.08 * (u(rng) - 0.5), 0.08 * (u(rng) - 0.5));
      if (!out.empty()) {
        const Placed& near = out[rng() % out.size()];
        const double a = 2.0 * M_PI * u(rng), reach = 0.5 * near.footprint.sizes().norm() + 0.03 + 0.07 * u(rng);
        xy = near.footprint.center() + reach * Eigen::Vector2d(std::cos(a), std::sin(a));
      }
      Placed p = place(o, rest, 2.0 * M_PI * u(rng), xy);
      bool free = table.contains(p.footprint);
      for (const auto& q : out)
        free = free &&
               !Eigen::AlignedBox2d(q.footprint.min().array() - 0.002, q.footprint.max().array() + 0.002).intersects(p.footprint);
      if (free) {
        out.push_back(p);
        break;
      }
    }
  }
  return out;
}

// The camera's path through a scene: 0.6-1.5 m from the objects' middle, looking down 20-60 degrees from
// in front (the wall behind), moving slowly round and in, as a hand-held or robot-held camera does.
struct CameraPath {
  Eigen::Vector3d target = Eigen::Vector3d::Zero();  // what it looks at
  double distance = 1.0, elevation = 0.6, azimuth = 0.0;
  double d_distance = 0.0, d_elevation = 0.0, d_azimuth = 0.0;  // per image

  Eigen::Matrix4d T_world_camera(int image) const {
    const double d = distance + image * d_distance, e = elevation + image * d_elevation, a = azimuth + image * d_azimuth;
    return look_at(target + d * Eigen::Vector3d(std::sin(a) * std::cos(e), -std::cos(a) * std::cos(e), std::sin(e)), target);
  }
};

CameraPath camera_path(const std::vector<Placed>& placed, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  CameraPath c;
  for (const auto& p : placed) c.target.head<2>() += p.footprint.center() / static_cast<double>(placed.size());
  c.target.z() = 0.04;
  const double deg = config::radians(1.0), sign = u(rng) < 0.5 ? -1.0 : 1.0;
  c.distance = 0.6 + 0.9 * u(rng);
  c.elevation = (20.0 + 40.0 * u(rng)) * deg;
  c.azimuth = (-40.0 + 80.0 * u(rng)) * deg;
  c.d_azimuth = sign * (0.03 + 0.07 * u(rng)) * deg;
  c.d_elevation = (u(rng) - 0.5) * 0.04 * deg;
  c.d_distance = (u(rng) - 0.5) * 0.002;
  return c;
}

// A camera frame's pixels rendered and measured: the scene's exact depth and colour, and each instance's
// exact depth alone.
struct Rendered {
  std::vector<float> scene_m;
  assets::Image colour;
  std::vector<std::vector<float>> alone_m;
};

class Scenery {
 public:
  Scenery(engine::Renderer& renderer, const alignment::CameraIntrinsics& k)
      : renderer_(renderer),
        camera_(k, 0.1, 10.0),
        depth_(renderer.make_depth_camera(k.width_px, k.height_px)),
        colour_(renderer.make_offscreen(k.width_px, k.height_px)) {}

  void set_room(const std::vector<Box>& boxes) {
    room_.clear();
    for (const auto& b : boxes) room_.push_back(renderer_.add_model(assets::make_box(b.min, b.max, b.rgba)));
    boxes_ = boxes.size();
  }

  Rendered render(const std::vector<Placed>& placed, const Eigen::Matrix4d& T_world_camera) {
    const Eigen::Matrix4d T_camera_world = T_world_camera.inverse();
    std::vector<engine::DrawItem> depth_items, colour_items;
    for (const std::size_t id : room_)
      depth_items.emplace_back(id, T_camera_world), colour_items.emplace_back(id, T_camera_world);
    for (const auto& p : placed) {
      depth_items.emplace_back(p.object->depth_id, T_camera_world * p.T_world_model);
      colour_items.emplace_back(p.object->colour_id, T_camera_world * p.T_world_model);
    }
    Rendered out;
    out.scene_m = depth(depth_items);
    renderer_.draw_frame(*colour_, camera_, colour_items);
    out.colour = colour_->read_back();
    for (std::size_t i = 0; i < placed.size(); ++i) out.alone_m.push_back(depth({depth_items[boxes_ + i]}));
    return out;
  }

 private:
  std::vector<float> depth(const std::vector<engine::DrawItem>& items) {
    renderer_.draw_frame(*depth_, camera_, items);
    return depth_->read_back_depth().z_m;
  }
  engine::Renderer& renderer_;
  config::Camera camera_;
  std::unique_ptr<engine::RenderTarget> depth_, colour_;
  std::vector<std::size_t> room_;
  std::size_t boxes_ = 0;
};

std::string numbered(int id, const char* ext) {
  char name[32];
  std::snprintf(name, sizeof name, "%06d%s", id, ext);
  return name;
}

json matrix_json(const Eigen::Matrix3d& R) {
  json out = json::array();
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) out.push_back(R(r, c));
  return out;
}

json vector_mm(const Eigen::Vector3d& t_m) { return json::array({1000.0 * t_m.x(), 1000.0 * t_m.y(), 1000.0 * t_m.z()}); }

// Where an instance shows, counted as BOP counts it, and its mask_visib image.
struct Visibility {
  std::vector<std::uint8_t> mask;  // 8-bit grey, 255 where visible, as BOP's mask_visib
  int all = 0, visible = 0, valid = 0;
  Eigen::AlignedBox2i all_box, visible_box;
};

Visibility visibility(const std::vector<float>& alone, const std::vector<float>& scene, const std::vector<float>& measured, int w,
                      int h) {
  Visibility v;
  v.mask.assign(static_cast<std::size_t>(w) * h, 0);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const auto i = static_cast<std::size_t>(y) * w + x;
      if (!(alone[i] > 0.0F)) continue;
      ++v.all;
      v.all_box.extend(Eigen::Vector2i(x, y));
      if (!(std::abs(scene[i] - alone[i]) < kSameSurfaceM)) continue;
      ++v.visible;
      v.valid += alignment::has_depth(measured[i]) ? 1 : 0;
      v.visible_box.extend(Eigen::Vector2i(x, y));
      v.mask[i] = 255;
    }
  return v;
}

json bbox(const Eigen::AlignedBox2i& b) {
  if (b.isEmpty()) return json::array({-1, -1, -1, -1});
  return json::array({b.min().x(), b.min().y(), b.sizes().x() + 1, b.sizes().y() + 1});
}

// The real sensor's depth from the exact one, stored as the real frames are (0.1 mm units).
assets::Gray16Image depth_png(const alignment::DepthImage& d) {
  assets::Gray16Image png{d.width, d.height, std::vector<std::uint16_t>(d.depth_m.size(), 0)};
  for (std::size_t i = 0; i < d.depth_m.size(); ++i) {
    const double units = d.depth_m[i] * 1000.0 / kDepthUnitMm;
    if (alignment::has_depth(d.depth_m[i]) && units < 65535.0) png.values[i] = static_cast<std::uint16_t>(std::lround(units));
  }
  return png;
}

struct SceneJson {
  json camera = json::object(), gt = json::object(), info = json::object();
};

// One image of a scene: depth under the sensor model, colour, each instance's mask and annotations.
int write_image(const fs::path& folder, int image, const std::vector<Placed>& placed, const Eigen::Matrix4d& T_world_camera,
                Scenery& scenery, const DatasetOptions& options, std::uint32_t seed, SceneJson& out) {
  const alignment::CameraIntrinsics& k = options.camera;
  Rendered r = scenery.render(placed, T_world_camera);
  const alignment::DepthImage measured =
      alignment::apply_kinect_v1_noise({k.width_px, k.height_px, r.scene_m, 0.0}, k, options.sensor, seed);
  assets::write_png_gray16(folder / "depth" / numbered(image, ".png"), depth_png(measured));
  add_colour_noise(r.colour, seed);
  assets::write_png(folder / "rgb" / numbered(image, ".png"), r.colour);
  const Eigen::Matrix4d T_camera_world = T_world_camera.inverse();
  json gt = json::array(), info = json::array();
  for (std::size_t i = 0; i < placed.size(); ++i) {
    const Visibility v = visibility(r.alone_m[i], r.scene_m, measured.depth_m, k.width_px, k.height_px);
    if (v.all == 0) continue;  // outside the picture: not annotated, as BOP leaves such objects out
    const Eigen::Matrix4d T = T_camera_world * placed[i].T_world_model;
    assets::write_png_gray8(folder / "mask_visib" / (numbered(image, "_") + numbered(static_cast<int>(gt.size()), ".png")),
                            k.width_px, k.height_px, v.mask);
    gt.push_back({{"cam_R_m2c", matrix_json(T.topLeftCorner<3, 3>())},
                  {"cam_t_m2c", vector_mm(T.topRightCorner<3, 1>())},
                  {"obj_id", placed[i].object->id}});
    info.push_back({{"bbox_obj", bbox(v.all_box)},
                    {"bbox_visib", bbox(v.visible_box)},
                    {"px_count_all", v.all},
                    {"px_count_visib", v.visible},
                    {"px_count_valid", v.valid},
                    {"visib_fract", static_cast<double>(v.visible) / v.all}});
  }
  const std::string key = std::to_string(image);
  out.camera[key] = {{"cam_K", {k.fx_px, 0.0, k.cx_px, 0.0, k.fy_px, k.cy_px, 0.0, 0.0, 1.0}},
                     {"depth_scale", kDepthUnitMm},
                     {"cam_R_w2c", matrix_json(T_camera_world.topLeftCorner<3, 3>())},
                     {"cam_t_w2c", vector_mm(T_camera_world.topRightCorner<3, 1>())}};
  out.gt[key] = gt;
  out.info[key] = info;
  return static_cast<int>(gt.size());
}

// One scene, written beside its place (`.SCENE.partial`) and renamed into it when whole. Returns its
// images; 0 (nothing left behind) when a stop came before its first.
int write_scene(const fs::path& split, int scene, const std::vector<Object>& objects, Scenery& scenery,
                const DatasetOptions& options, DatasetSummary& summary) {
  std::mt19937 rng(options.seed * 1000003U + static_cast<std::uint32_t>(scene));
  scenery.set_room(room(rng));
  const std::vector<Placed> placed = arrange(objects, rng);
  const CameraPath path = camera_path(placed, rng);
  const fs::path done = split / numbered(scene, ""), partial = split / ("." + numbered(scene, ".partial"));
  fs::remove_all(partial);
  for (const char* sub : {"depth", "rgb", "mask_visib"}) fs::create_directories(partial / sub);
  SceneJson json_files;
  int images = 0;
  try {
    for (; images < options.images; ++images) {
      if (options.stop_requested && options.stop_requested()) break;
      const auto seed = options.seed * 7919U + static_cast<std::uint32_t>(scene * 1009 + images);
      summary.instances += write_image(partial, images, placed, path.T_world_camera(images), scenery, options, seed, json_files);
      ++summary.images;
      if (options.image_done) options.image_done(summary.images);
    }
    if (images > 0) {
      config::write_file_atomically(partial / "scene_camera.json", json_files.camera.dump(1));
      config::write_file_atomically(partial / "scene_gt.json", json_files.gt.dump(1));
      config::write_file_atomically(partial / "scene_gt_info.json", json_files.info.dump(1));
      fs::rename(partial, done);
    } else {
      fs::remove_all(partial);
    }
  } catch (...) {
    std::error_code ec;
    fs::remove_all(partial, ec);
    throw;
  }
  return images;
}

}  // namespace

alignment::CameraIntrinsics ycbv_camera() { return {640, 480, 1066.778, 1067.487, 312.9869, 241.3109}; }

DatasetSummary write_twin_dataset(const fs::path& out, const DatasetOptions& options, engine::Renderer& renderer) {
  std::vector<Object> objects = objects_for(options);
  DatasetSummary summary;
  if (objects.empty()) {  // stopped while loading: nothing written
    summary.interrupted = true;
    return summary;
  }
  for (auto& o : objects) {
    o.depth_id = renderer.add_model(o.model);
    o.colour_id = renderer.add_model(coloured(o.model, albedo_for(o.id)));
  }
  summary.objects = static_cast<int>(objects.size());
  write_models(out / "models", objects);
  Scenery scenery(renderer, options.camera);
  for (int s = 0; s < options.scenes; ++s) {
    const int images = write_scene(out / "test", s, objects, scenery, options, summary);
    summary.scenes += images > 0 ? 1 : 0;
    if (images < options.images) {
      summary.interrupted = true;
      break;
    }
  }
  return summary;
}

}  // namespace projbot::twin
