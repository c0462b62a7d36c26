// A BOP object's model loaded for estimation and scoring: its own translation unit, so that the BOP
// reader (bop.cpp, which the fuzzers build without PCL) does not pull in the acquisition.

#include "projbot/alignment/bop.hpp"
#include "projbot/assets/model.hpp"

namespace projbot::alignment {

BopModel load_bop_model(const BopObject& object, double scale) {
  assets::Model mesh = assets::load_model(object.model);
  assets::scale_and_recenter(mesh, scale, false);
  BopModel m;
  m.info = &object;
  m.cloud = model_cloud_from(mesh);
  for (const auto& p : mesh.primitives)
    for (const auto& v : p.vertices) m.vertices.emplace_back(v.position[0], v.position[1], v.position[2]);
  m.centre = mesh.bounds().center();
  return m;
}

}  // namespace projbot::alignment
