#pragma once
// The real depth camera beside the twin's, both at a BOP dataset's ground truth (`projbot bench sensor`,
// issue 41): what the real sensor does that the twin's Kinect model does or does not (noise inside the
// silhouette, missing pixels, the band of mixed pixels and the shadow outside it, depth quantisation).

#include <array>
#include <cstdint>
#include <map>
#include <memory>
#include <vector>

#include "projbot/alignment/bop.hpp"
#include "projbot/engine/renderer.hpp"

namespace projbot::bench {

constexpr int kRings = 4;                     ///< rings of pixels outside the silhouette, 1..kRings px away
constexpr std::array<int, 3> kLags{1, 3, 8};  ///< the noise's differences this many pixels apart along a row

/// What one sensor showed over all instances (counts of pixels; depths in mm).
struct SensorStats {
  std::vector<double> residual_mm;  // depth - rendered truth, silhouette interior, both valid
  long interior = 0, interior_missing = 0, edge = 0, edge_missing = 0;
  std::array<long, kRings + 1> ring{}, ring_missing{}, ring_object{}, ring_between{};
  long left = 0, left_missing = 0, right = 0, right_missing = 0;  // rings 1..3, by side of the silhouette
  std::vector<double> step_per_z2;                                // nonzero depth steps between neighbours / z^2
  std::vector<double> offset_mm;  // per instance: the median residual (what the ground truth's own error explains)
  std::vector<double> noise_mm;   // residuals less their instance's plane (offset and tilt): the sensor's noise
  std::array<std::vector<double>, 3> lag_difference;  // |noise - noise kLags[i] px to the right|

  /// `more`'s pixels and instances added to these.
  void add(const SensorStats& more);
};

/// The three sensors over the images measured: the real one, the twin's published Kinect v1 model, and
/// the one fitted to real frames.
struct SensorComparison {
  SensorStats real, twin, fitted;
  int instances = 0, images = 0;

  /// `more`'s images added to these (an image measured apart, then kept whole).
  void add(const SensorComparison& more);
};

/// Renders the dataset's models at their ground truth through each image's camera and measures each
/// image's instances under the three sensors. Owns a renderer (headless); not thread-safe.
class SensorBench {
 public:
  /// `scale`: model units to metres. Throws assets::AssetError naming a model that cannot be read.
  SensorBench(const alignment::BopDataset& data, double scale);
  /// Adds image `image`'s instances with at least `min_visible` visible pixels to `out`; the twin's noise
  /// seeded by `seed` and the image's id.
  void image(const alignment::BopScene& scene, const alignment::BopImage& image, int min_visible, std::uint32_t seed,
             SensorComparison& out);

 private:
  std::vector<float> render(const alignment::BopImage& image, const std::vector<const alignment::BopInstance*>& which, int width,
                            int height);
  engine::Renderer renderer_;
  std::map<int, std::size_t> ids_;
  std::unique_ptr<engine::RenderTarget> target_;
  int width_ = 0, height_ = 0;
};

}  // namespace projbot::bench
