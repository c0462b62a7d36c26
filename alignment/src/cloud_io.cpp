// PCD and PLY through PCL's readers: the only translation unit with pcl/io.

#include <pcl/io/pcd_io.h>
#include <pcl/io/ply_io.h>
#include <pcl/point_types.h>

#include <algorithm>
#include <cctype>
#include <functional>

#include "file_kind.hpp"
#include "pcd_header.hpp"
#include "ply_body.hpp"
#include "projbot/alignment/depth.hpp"
#include "projbot/config/isolated_read.hpp"
#include "projbot/config/paths.hpp"

namespace projbot::alignment {
namespace {

using Cloud = pcl::PointCloud<pcl::PointXYZ>;

// PCL's readers are not safe on hostile files even after our header check: the PLY parser asserts
// (abort) on a face list that names a missing vertex, the PCD reader read uninitialised memory on a
// fuzzed binary file (a 94 TB string, or SIGSEGV). They run in a child process, whose cloud comes back
// as PCL's return code, width, height and x y z floats.
int load_isolated(const std::filesystem::path& path, const std::string& kind, const std::function<int(Cloud&)>& load,
                  Cloud& cloud) {
  std::string bytes;
  try {
    bytes = config::read_isolated(path, {kind, "PCL's reader"}, [&](config::ReadProgress&) {
      Cloud read;
      config::Bytes out;
      try {
        out.put<std::int32_t>(load(read));
      } catch (const std::bad_alloc&) {
        throw;
      } catch (const std::exception& e) {  // PCLException, and std::stoi's from its header parser
        throw AlignmentError(path.string() + ": malformed " + kind + " (PCL's reader failed on it: " + e.what() + ")");
      }
      out.put<std::uint32_t>(read.width);
      out.put<std::uint32_t>(read.height);
      std::vector<float> xyz;
      xyz.reserve(3 * read.size());
      for (const auto& p : read) xyz.insert(xyz.end(), {p.x, p.y, p.z});
      out.put_vector(xyz);
      return out.take();
    });
  } catch (const config::IsolatedReadError& e) {
    throw AlignmentError(e.what());
  }
  config::BytesReader in(bytes);
  const auto rc = in.get<std::int32_t>();
  const auto width = in.get<std::uint32_t>();
  const auto height = in.get<std::uint32_t>();
  const auto xyz = in.get_vector<float>();
  cloud.clear();
  for (std::size_t i = 0; i + 2 < xyz.size(); i += 3) cloud.push_back({xyz[i], xyz[i + 1], xyz[i + 2]});
  if (static_cast<std::size_t>(width) * height == cloud.size()) {
    cloud.width = width;
    cloud.height = height;
  }
  return rc;
}

}  // namespace

PointCloud read_cloud(const std::filesystem::path& path) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) throw AlignmentError(path.string() + ": is a folder, not a point cloud file");
  if (const std::string kind = config::input_file_problem(path); !kind.empty())  // a FIFO is named as one, not "no such"
    throw AlignmentError(path.string() + (kind == "does not exist" ? std::string(": no such point cloud file") : ": " + kind));
  const std::string ext = detail::lower_extension(path);
  Cloud cloud;
  int rc = -1;
  // PCL prints its own complaints to stderr; ours, below, names the file and what to do.
  pcl::console::setVerbosityLevel(pcl::console::L_ALWAYS);
  try {
    if (ext == ".pcd") {
      const detail::PcdHeader header = detail::check_pcd(path);  // PCL's reader crashes on what this refuses
      rc = load_isolated(
          path, "PCD file", [&](Cloud& c) { return pcl::io::loadPCDFile(path.string(), c); }, cloud);
      if (rc >= 0 && cloud.size() != header.points)
        throw AlignmentError(path.string() + ": read " + std::to_string(cloud.size()) + " points, the header claims " +
                             std::to_string(header.points) + " (malformed data section?)");
    } else if (ext == ".ply") {
      const detail::PlyCounts counts = detail::check_ply_body(path);  // PCL reads the declared counts, ignores the rest
      if (!counts.vertex_xyz)  // PCL reads such a file as points at the origin, and the alignment then fails
        throw AlignmentError(path.string() + ": its vertex element has no x, y and z properties (not a point cloud)");
      const std::uint64_t vertices = counts.vertices;
      rc = load_isolated(
          path, "PLY file", [&](Cloud& c) { return pcl::io::loadPLYFile(path.string(), c); }, cloud);
      if (rc >= 0 && cloud.size() != vertices)
        throw AlignmentError(path.string() + ": read " + std::to_string(cloud.size()) + " points, the header declares " +
                             std::to_string(vertices) + " vertices");
    } else {
      throw AlignmentError(path.string() + ": unknown point cloud format (use .pcd or .ply)");
    }
  } catch (const pcl::PCLException& e) {
    throw AlignmentError(path.string() + ": cannot read point cloud: " + e.what());
  } catch (const std::bad_alloc&) {
    throw AlignmentError(path.string() + ": out of memory reading the point cloud");
  } catch (const AlignmentError&) {
    throw;
  } catch (const std::exception& e) {  // PCL's header parser lets std::stoi's and boost's exceptions out
    throw AlignmentError(path.string() + ": malformed " + ext.substr(1) + " file (PCL's reader failed on it: " + e.what() + ")");
  }
  if (rc < 0) throw AlignmentError(path.string() + ": cannot read point cloud (malformed " + ext.substr(1) + " file?)");
  if (cloud.empty()) throw AlignmentError(path.string() + ": the point cloud holds no points (malformed or empty file?)");
  PointCloud out;
  out.width = static_cast<int>(cloud.width);
  out.height = static_cast<int>(cloud.height);
  if (static_cast<std::size_t>(out.width) * static_cast<std::size_t>(std::max(out.height, 1)) != cloud.size()) {
    out.width = static_cast<int>(cloud.size());
    out.height = 1;
  }
  out.points.reserve(cloud.size());
  for (const auto& p : cloud) out.points.emplace_back(p.x, p.y, p.z);
  return out;
}

}  // namespace projbot::alignment
