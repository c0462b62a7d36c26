// A BOP object's model loaded for estimation and scoring: its own translation unit, so that the BOP
// reader (bop.cpp, which the fuzzers build without PCL) does not pull in the acquisition.

#include <algorithm>

#include "projbot/alignment/bop.hpp"
#include "projbot/assets/model.hpp"

namespace projbot::alignment {
namespace {

// ADD and ADD-S average over the mesh's vertices: BOP's own models have about 8000, all scored. A mesh of
// a million took seconds per score (ADD-S: a k-d tree over them and a query each), so a stop request waited
// on it; past this many, every k-th vertex is scored (an even subsample: the same mean within noise).
constexpr std::size_t kMaxScoredVertices = 30000;

}  // namespace

BopModel load_bop_model(const BopObject& object, double scale) {
  assets::Model mesh = assets::load_model(object.model);
  assets::scale_and_recenter(mesh, scale, false);
  BopModel m;
  m.info = &object;
  m.cloud = model_cloud_from(mesh);
  std::size_t count = 0;
  for (const auto& p : mesh.primitives) count += p.vertices.size();
  const std::size_t stride = (count + kMaxScoredVertices - 1) / kMaxScoredVertices;
  std::size_t i = 0;
  for (const auto& p : mesh.primitives)
    for (const auto& v : p.vertices)
      if (i++ % std::max<std::size_t>(stride, 1) == 0) m.vertices.emplace_back(v.position[0], v.position[1], v.position[2]);
  m.centre = mesh.bounds().center();
  return m;
}

}  // namespace projbot::alignment
