// Depth images and their back-projection. PNG through assets (stb), TIFF through libtiff, the grabber XML
// through Boost.PropertyTree; no PCL here.

#include "projbot/alignment/depth.hpp"

#include <tiffio.h>

#include <boost/property_tree/ptree.hpp>
#include <boost/property_tree/xml_parser.hpp>
#include <cmath>
#include <filesystem>
#include <memory>

#include "projbot/assets/image.hpp"

namespace projbot::alignment {

std::size_t PointCloud::finite_count() const {
  std::size_t n = 0;
  for (const auto& p : points) n += p.allFinite() ? 1 : 0;
  return n;
}

DepthImage read_depth_png(const std::filesystem::path& path, double units_per_metre) {
  if (!(units_per_metre > 0.0) || !std::isfinite(units_per_metre))
    throw AlignmentError(path.string() + ": depth scale must be a finite number > 0 units per metre");
  assets::Gray16Image png;
  try {
    png = assets::read_png_gray16(path);
  } catch (const assets::AssetError& e) {
    throw AlignmentError(e.what());
  }
  DepthImage d;
  d.width = png.width;
  d.height = png.height;
  d.depth_m.resize(png.values.size());
  for (std::size_t i = 0; i < d.depth_m.size(); ++i) d.depth_m[i] = static_cast<float>(png.values[i] / units_per_metre);
  return d;
}

DepthImage read_depth_tiff(const std::filesystem::path& path, double metres_per_unit) {
  if (!(metres_per_unit > 0.0) || !std::isfinite(metres_per_unit))
    throw AlignmentError(path.string() + ": depth scale must be a finite number > 0 metres per unit");
  TIFFSetWarningHandler(nullptr);  // libtiff warns on stderr about harmless private tags
  TIFFSetErrorHandler(nullptr);
  std::unique_ptr<TIFF, void (*)(TIFF*)> tif(TIFFOpen(path.c_str(), "r"), TIFFClose);
  if (!tif) throw AlignmentError(path.string() + ": cannot open TIFF");
  std::uint32_t w = 0, h = 0;
  std::uint16_t bits = 0, samples = 1;
  TIFFGetField(tif.get(), TIFFTAG_IMAGEWIDTH, &w);
  TIFFGetField(tif.get(), TIFFTAG_IMAGELENGTH, &h);
  TIFFGetFieldDefaulted(tif.get(), TIFFTAG_BITSPERSAMPLE, &bits);
  TIFFGetFieldDefaulted(tif.get(), TIFFTAG_SAMPLESPERPIXEL, &samples);
  if (bits != 16 || samples != 1 || w == 0 || h == 0 || w > 16384 || h > 16384)
    throw AlignmentError(path.string() + ": a depth TIFF must be 16-bit single-channel (this one: " + std::to_string(bits) +
                         " bits, " + std::to_string(samples) + " samples, " + std::to_string(w) + "x" + std::to_string(h) + ")");
  // The pixels a header claims must fit in the file: uncompressed 2 bytes each, compressed at most 4096:1
  // (LZW's best, on constant rows). The fuzzer's 145-byte file claimed 11012 x 15352 (676 MB).
  std::uint16_t compression = COMPRESSION_NONE;
  TIFFGetFieldDefaulted(tif.get(), TIFFTAG_COMPRESSION, &compression);
  std::error_code ec;
  const auto file_bytes = static_cast<double>(std::filesystem::file_size(path, ec));
  const double ratio = compression == COMPRESSION_NONE ? 1.0 : 4096.0;
  if (!ec && 2.0 * w * h > ratio * file_bytes + 65536.0)
    throw AlignmentError(path.string() + ": the TIFF header claims " + std::to_string(w) + "x" + std::to_string(h) +
                         " pixels, more than its " + std::to_string(static_cast<std::uint64_t>(file_bytes)) + " bytes can hold");
  DepthImage d;
  d.width = static_cast<int>(w);
  d.height = static_cast<int>(h);
  d.depth_m.resize(static_cast<std::size_t>(w) * h);
  std::vector<std::uint16_t> row(TIFFScanlineSize(tif.get()) / 2 + 1);
  for (std::uint32_t y = 0; y < h; ++y) {
    if (TIFFReadScanline(tif.get(), row.data(), y, 0) < 0)
      throw AlignmentError(path.string() + ": TIFF row " + std::to_string(y) + " is corrupt");
    for (std::uint32_t x = 0; x < w; ++x)
      d.depth_m[static_cast<std::size_t>(y) * w + x] = static_cast<float>(row[x] * metres_per_unit);
  }
  return d;
}

GrabberCalibration read_pcl_grabber_xml(const std::filesystem::path& path, int width_px, int height_px) {
  boost::property_tree::ptree tree;
  try {
    boost::property_tree::read_xml(path.string(), tree);
    GrabberCalibration c;
    c.intrinsics.width_px = width_px;
    c.intrinsics.height_px = height_px;
    c.intrinsics.fx_px = tree.get<double>("depth.focal_length_x");
    c.intrinsics.fy_px = tree.get<double>("depth.focal_length_y");
    c.intrinsics.cx_px = tree.get<double>("depth.principal_point_x");
    c.intrinsics.cy_px = tree.get<double>("depth.principal_point_y");
    c.metres_per_unit = tree.get<double>("depth.z_multiplication_factor", 0.001);
    if (!(c.intrinsics.fx_px > 0) || !(c.intrinsics.fy_px > 0) || !(c.metres_per_unit > 0))
      throw AlignmentError(path.string() + ": focal lengths and z_multiplication_factor must be > 0");
    return c;
  } catch (const boost::property_tree::ptree_error& e) {
    throw AlignmentError(path.string() + ": not a PCL grabber calibration: " + e.what());
  }
}

Plane floor_in_camera(const Eigen::Matrix4d& T_world_camera) {
  // World z of a camera-frame point p: row 3 of R p + t_z.
  Plane p;
  p.normal = T_world_camera.block<1, 3>(2, 0).transpose();
  p.d = T_world_camera(2, 3);
  return p;
}

DepthImage without_plane(const DepthImage& depth, const CameraIntrinsics& k, const Plane& plane, double margin_m) {
  if (depth.width != k.width_px || depth.height != k.height_px) throw AlignmentError("depth image and intrinsics differ in size");
  DepthImage out = depth;
  for (int y = 0; y < depth.height; ++y)
    for (int x = 0; x < depth.width; ++x) {
      float& z = out.depth_m[static_cast<std::size_t>(y) * depth.width + x];
      if (!(z > 0.0F)) continue;
      const Eigen::Vector3d p = k.back_project(x, y, z);
      if (plane.height_of(p) < margin_m) z = 0.0F;
    }
  return out;
}

PointCloud depth_to_cloud(const DepthImage& depth, const CameraIntrinsics& k, double min_m, double max_m) {
  if (depth.width != k.width_px || depth.height != k.height_px)
    throw AlignmentError("depth image is " + std::to_string(depth.width) + "x" + std::to_string(depth.height) +
                         " but the intrinsics are for " + std::to_string(k.width_px) + "x" + std::to_string(k.height_px));
  if (!(k.fx_px > 0) || !(k.fy_px > 0)) throw AlignmentError("depth intrinsics need fx, fy > 0");
  PointCloud c;
  c.width = depth.width;
  c.height = depth.height;
  c.points.resize(depth.depth_m.size());
  const float nan = std::nanf("");
  for (int y = 0; y < depth.height; ++y)
    for (int x = 0; x < depth.width; ++x) {
      const float z = depth.at(x, y);
      auto& p = c.points[static_cast<std::size_t>(y) * depth.width + x];
      if (!(z > 0.0F && z >= min_m && z <= max_m)) {  // also false for NaN
        p = {nan, nan, nan};
        continue;
      }
      p = k.back_project(x, y, z).cast<float>();
    }
  return c;
}

PointCloud finite_points(const PointCloud& cloud) {
  PointCloud out;
  out.points.reserve(cloud.points.size());
  for (const auto& p : cloud.points)
    if (p.allFinite()) out.points.push_back(p);
  out.width = static_cast<int>(out.points.size());
  out.height = 1;
  return out;
}

}  // namespace projbot::alignment
