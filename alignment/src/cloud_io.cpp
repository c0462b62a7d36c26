// PCD and PLY through PCL's readers: the only translation unit with pcl/io.

#include <pcl/io/pcd_io.h>
#include <pcl/io/ply_io.h>
#include <pcl/point_types.h>

#include <algorithm>
#include <cctype>

#include "file_kind.hpp"
#include "pcd_header.hpp"
#include "projbot/alignment/depth.hpp"

namespace projbot::alignment {

PointCloud read_cloud(const std::filesystem::path& path) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) throw AlignmentError(path.string() + ": is a folder, not a point cloud file");
  if (!std::filesystem::is_regular_file(path, ec)) throw AlignmentError(path.string() + ": no such point cloud file");
  const std::string ext = detail::lower_extension(path);
  pcl::PointCloud<pcl::PointXYZ> cloud;
  int rc = -1;
  // PCL prints its own complaints to stderr; ours, below, names the file and what to do.
  pcl::console::setVerbosityLevel(pcl::console::L_ALWAYS);
  try {
    if (ext == ".pcd") {
      const detail::PcdHeader header = detail::check_pcd(path);  // PCL's reader crashes on what this refuses
      rc = pcl::io::loadPCDFile(path.string(), cloud);
      if (rc >= 0 && cloud.size() != header.points)
        throw AlignmentError(path.string() + ": read " + std::to_string(cloud.size()) + " points, the header claims " +
                             std::to_string(header.points) + " (malformed data section?)");
    } else if (ext == ".ply") {
      rc = pcl::io::loadPLYFile(path.string(), cloud);
    } else {
      throw AlignmentError(path.string() + ": unknown point cloud format (use .pcd or .ply)");
    }
  } catch (const pcl::PCLException& e) {
    throw AlignmentError(path.string() + ": cannot read point cloud: " + e.what());
  } catch (const std::bad_alloc&) {
    throw AlignmentError(path.string() + ": out of memory reading the point cloud");
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
