// Capture folders and calibration files on disk.

#include "capture_io.hpp"

#include <unistd.h>
#include <yaml-cpp/yaml.h>

#include <cctype>
#include <cmath>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <optional>
#include <sstream>

#include "projbot/assets/image.hpp"
#include "projbot/calibrate/procam.hpp"
#include "projbot/config/output_file.hpp"
#include "projbot/config/yaml_keys.hpp"
#include "yaml_file.hpp"

namespace projbot::calibrate {
namespace fs = std::filesystem;
namespace {

constexpr int kMinProjectorSide = 8, kMaxProjectorSide = 16384;  // pixels

std::string two_digits(int i) { return (i < 10 ? "0" : "") + std::to_string(i); }

// Names compared with runs of digits as numbers: 2.png before 10.png.
bool natural_less(const std::string& a, const std::string& b) {
  std::size_t i = 0, j = 0;
  while (i < a.size() && j < b.size()) {
    if (std::isdigit(static_cast<unsigned char>(a[i])) && std::isdigit(static_cast<unsigned char>(b[j]))) {
      std::size_t ie = i, je = j;
      while (ie < a.size() && std::isdigit(static_cast<unsigned char>(a[ie]))) ++ie;
      while (je < b.size() && std::isdigit(static_cast<unsigned char>(b[je]))) ++je;
      const std::string na = a.substr(i, ie - i), nb = b.substr(j, je - j);
      const std::string ta = na.substr(std::min(na.find_first_not_of('0'), na.size()));
      const std::string tb = nb.substr(std::min(nb.find_first_not_of('0'), nb.size()));
      if (ta.size() != tb.size()) return ta.size() < tb.size();
      if (ta != tb) return ta < tb;
      i = ie;
      j = je;
    } else {
      if (a[i] != b[j]) return a[i] < b[j];
      ++i;
      ++j;
    }
  }
  return a.size() - i < b.size() - j;
}

bool is_image(const fs::path& p) {
  std::string ext = p.extension().string();
  for (char& ch : ext) ch = static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
  return ext == ".png" || ext == ".jpg" || ext == ".jpeg" || ext == ".bmp" || ext == ".tif" || ext == ".tiff" || ext == ".pgm";
}

std::vector<fs::path> images_in(const fs::path& folder) {
  std::vector<fs::path> out;
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(folder, ec))
    if (e.is_regular_file(ec) && is_image(e.path())) out.push_back(e.path());
  std::sort(out.begin(), out.end(),
            [](const fs::path& a, const fs::path& b) { return natural_less(a.filename().string(), b.filename().string()); });
  return out;
}

}  // namespace

CaptureWriter::CaptureWriter(fs::path out) : out_(std::move(out)) {
  std::error_code ec;
  if (fs::exists(out_, ec) && !(fs::is_directory(out_, ec) && fs::is_empty(out_, ec)))
    throw CalibrationError("'" + out_.string() + "' exists and is not an empty folder; name a new one");
  const fs::path parent = out_.has_parent_path() ? out_.parent_path() : fs::path(".");
  temp_ = parent / ("." + out_.filename().string() + ".partial-" + std::to_string(::getpid()));
  fs::remove_all(temp_, ec);
  if (!fs::create_directories(temp_, ec) || ec)
    throw CalibrationError("cannot create a folder in '" + parent.string() + "': " + (ec ? ec.message() : "unknown error"));
}

CaptureWriter::~CaptureWriter() {
  if (done_) return;
  std::error_code ec;
  fs::remove_all(temp_, ec);
}

std::string CaptureWriter::write_pose(int index, const std::vector<cv::Mat>& images) {
  const std::string name = "pose_" + two_digits(index);
  std::error_code ec;
  fs::create_directories(temp_ / name, ec);
  for (std::size_t k = 0; k < images.size(); ++k) {
    const fs::path file = temp_ / name / (two_digits(static_cast<int>(k)) + ".png");
    bool ok = false;
    try {
      ok = cv::imwrite(file.string(), images[k], {cv::IMWRITE_PNG_COMPRESSION, 1});
    } catch (const cv::Exception&) {
      ok = false;
    }
    if (!ok) throw CalibrationError("cannot write '" + file.string() + "' (disk full?)");
  }
  return name;
}

void CaptureWriter::finish(const CaptureManifest& m, const std::optional<Calibration>& truth) {
  std::ostringstream y;
  y << "# A projector-camera calibration capture (projbot calibrate): one folder per board pose, each with\n"
       "# the Gray-code images in OpenCV GrayCodePattern::generate() order, then white, then black.\n"
    << "format: projbot-procam-capture-1\n"
    << "projector: {width: " << m.projector_width << ", height: " << m.projector_height << "}\n"
    << "board: \"" << m.board.spec() << "\"\n"
    << "images_per_pose: " << images_per_pose(m.projector_width, m.projector_height) << "\n"
    << "poses:\n";
  for (const std::string& f : m.folders) y << "  - " << f << "\n";
  config::write_file_atomically(temp_ / "capture.yaml", y.str());
  if (truth) write_calibration(*truth, temp_ / "truth.yaml", "the truth this capture was simulated with");
  std::error_code ec;
  if (fs::exists(out_, ec)) fs::remove(out_, ec);  // an empty folder, checked at the start
  fs::rename(temp_, out_, ec);
  if (ec) throw CalibrationError("cannot move the capture into '" + out_.string() + "': " + ec.message());
  done_ = true;
}

namespace {

// The size of a folder's first image, or nothing when it cannot be read (read_pose says why later).
std::optional<cv::Size> first_image_size(const fs::path& folder) {
  const std::vector<fs::path> files = images_in(folder);
  if (files.empty()) return std::nullopt;
  try {
    assets::check_png_structure(files.front());
  } catch (const assets::AssetError&) {
    return std::nullopt;
  }
  const cv::Mat img = cv::imread(files.front().string(), cv::IMREAD_GRAYSCALE);
  if (img.empty()) return std::nullopt;
  return img.size();
}

// A projector side from the manifest, named with its key, line and the range it may take.
int projector_side(const YAML::Node& y, const char* key, const fs::path& file) {
  const YAML::Node p = y["projector"];
  const YAML::Node n = p.IsMap() ? p[key] : YAML::Node();
  const double v = n && n.IsScalar() ? n.as<double>(std::nan("")) : std::nan("");
  if (!(v >= kMinProjectorSide && v <= kMaxProjectorSide) || v != std::floor(v))
    throw CalibrationError(file.string() + (n ? ":" + std::to_string(n.Mark().line + 1) : std::string()) + ": projector." + key +
                           " must be a whole number of pixels, " + std::to_string(kMinProjectorSide) + ".." +
                           std::to_string(kMaxProjectorSide) + " (it is " +
                           (n && n.IsScalar() ? "'" + n.Scalar() + "'" : std::string("not given")) + ")");
  return static_cast<int>(v);
}

// Another tool's capture may keep the projected patterns beside the captures (procam-calibration's
// graycode_pattern/): folders of images at the projector's size are skipped with a note, unless every
// folder is (a camera as large as the projector: then none can be told apart).
void skip_pattern_folders(const fs::path& dir, CaptureManifest& m) {
  std::vector<std::string> kept, skipped;
  for (const std::string& name : m.folders) {
    const auto size = first_image_size(dir / name);
    (size && *size == cv::Size(m.projector_width, m.projector_height) ? skipped : kept).push_back(name);
  }
  if (skipped.empty() || kept.empty()) return;
  for (const std::string& name : skipped)
    m.notes.push_back("skipped '" + name + "': its images are at the projector's size (" + std::to_string(m.projector_width) +
                      "x" + std::to_string(m.projector_height) + "), the projected patterns rather than a capture");
  m.folders = kept;
}

}  // namespace

CaptureManifest read_manifest(const fs::path& dir, const SolveOptions& options) {
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) throw CalibrationError("'" + dir.string() + "' is not a folder");
  CaptureManifest m;
  const fs::path file = dir / "capture.yaml";
  if (fs::exists(file, ec)) {
    try {
      const YAML::Node y = detail::load_yaml(file, "a capture manifest");
      if (!y.IsMap() || y["format"].as<std::string>("") != "projbot-procam-capture-1")
        throw CalibrationError(file.string() + ": not a projbot capture (format: projbot-procam-capture-1)");
      m.projector_width = projector_side(y, "width", file);
      m.projector_height = projector_side(y, "height", file);
      m.board = Board::parse(y["board"].as<std::string>());
      for (const auto& p : y["poses"]) m.folders.push_back(p.as<std::string>());
    } catch (const YAML::ParserException& e) {
      throw CalibrationError(config::yaml_error_message(e, file.string()));
    } catch (const YAML::Exception& e) {
      throw CalibrationError(file.string() + ": " + e.what());
    }
    if (options.projector_size && *options.projector_size != std::pair(m.projector_width, m.projector_height))
      throw CalibrationError("--projector disagrees with " + file.string());
  } else {
    if (!options.projector_size || !options.board)
      throw CalibrationError("'" + dir.string() +
                             "' has no capture.yaml: give the projector's size and the board (--projector WxH --board SPEC)");
    std::tie(m.projector_width, m.projector_height) = *options.projector_size;
    std::vector<std::string> names;
    for (const auto& e : fs::directory_iterator(dir, ec))
      if (e.is_directory(ec) && !images_in(e.path()).empty()) names.push_back(e.path().filename().string());
    std::sort(names.begin(), names.end(), natural_less);
    m.folders = names;
    skip_pattern_folders(dir, m);
  }
  if (options.board) m.board = *options.board;
  if (m.projector_width < kMinProjectorSide || m.projector_height < kMinProjectorSide || m.projector_width > kMaxProjectorSide ||
      m.projector_height > kMaxProjectorSide)
    throw CalibrationError("projector size " + std::to_string(m.projector_width) + "x" + std::to_string(m.projector_height) +
                           " is out of range (each side " + std::to_string(kMinProjectorSide) + ".." +
                           std::to_string(kMaxProjectorSide) + " pixels)");
  if (m.folders.empty()) throw CalibrationError("'" + dir.string() + "' holds no pose folders with images");
  return m;
}

std::vector<BoardPose> read_board_poses(const fs::path& path) {
  std::vector<BoardPose> out;
  try {
    const YAML::Node y = detail::load_yaml(path, "a board-pose file");
    if (!y.IsMap() || !y["poses"] || !y["poses"].IsSequence() || y["poses"].size() == 0)
      throw CalibrationError(path.string() + ": expected 'poses: [{centre: [x, y, z], tilt_deg: [a, b, c]}, ...]'");
    for (const auto& p : y["poses"]) {
      BoardPose b;
      const auto vec = [&](const char* key, Eigen::Vector3d& v) {
        const YAML::Node n = p[key];
        if (!n.IsSequence() || n.size() != 3)
          throw CalibrationError(path.string() + ":" + std::to_string(p.Mark().line + 1) + ": " + key + ": expected 3 numbers");
        for (std::size_t k = 0; k < 3; ++k) v[static_cast<Eigen::Index>(k)] = n[k].as<double>();
        if (!v.allFinite()) throw CalibrationError(path.string() + ": " + key + " is not finite");
      };
      vec("centre", b.centre_m);
      if (p["tilt_deg"]) vec("tilt_deg", b.tilt_deg);
      if (b.centre_m.z() <= 0.1)
        throw CalibrationError(path.string() + ":" + std::to_string(p.Mark().line + 1) +
                               ": centre must lie in front of the camera (z > 0.1 m)");
      out.push_back(b);
    }
  } catch (const YAML::ParserException& e) {
    throw CalibrationError(config::yaml_error_message(e, path.string()));
  } catch (const YAML::Exception& e) {
    throw CalibrationError(path.string() + ": " + e.what());
  }
  return out;
}

std::vector<cv::Mat> read_pose(const fs::path& folder, std::size_t expected) {
  const std::vector<fs::path> files = images_in(folder);
  if (files.size() != expected)
    throw CalibrationError("'" + folder.string() + "': " + std::to_string(files.size()) + " images, expected " +
                           std::to_string(expected) + " (the Gray-code patterns and inverses, then white and black)");
  std::vector<cv::Mat> images;
  for (const fs::path& f : files) {
    cv::Mat img;
    try {
      assets::check_png_structure(f);  // a reason of ours rather than libpng's line on stderr
    } catch (const assets::AssetError& e) {
      throw CalibrationError(e.what());
    }
    try {
      img = cv::imread(f.string(), cv::IMREAD_GRAYSCALE);
    } catch (const cv::Exception&) {
      img.release();
    }
    if (img.empty()) throw CalibrationError("'" + f.string() + "': cannot read the image");
    if (!images.empty() && img.size() != images.front().size())
      throw CalibrationError("'" + f.string() + "': " + std::to_string(img.cols) + "x" + std::to_string(img.rows) +
                             ", the folder's first image is " + std::to_string(images.front().cols) + "x" +
                             std::to_string(images.front().rows));
    images.push_back(img);
  }
  return images;
}

}  // namespace projbot::calibrate
