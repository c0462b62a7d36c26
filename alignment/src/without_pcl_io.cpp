// The portable build (PROJBOT_PORTABLE, tools/bundle.sh) leaves PCL's io module out: it links VTK, 60 MiB.
// Reading PCD and PLY scans then says so; depth images, BOP frames and models read as in the full build.
#include "projbot/alignment/depth.hpp"

namespace projbot::alignment {

PointCloud read_cloud(const std::filesystem::path& path) {
  throw AlignmentError(path.string() +
                       ": PCD and PLY scans are read with PCL's io module, which this portable build leaves out "
                       "(tools/bundle.sh): use the full build");
}

}  // namespace projbot::alignment
