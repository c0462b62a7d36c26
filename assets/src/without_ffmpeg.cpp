// The portable build (PROJBOT_PORTABLE, tools/bundle.sh) leaves FFmpeg out: its libraries and theirs come to
// 170 MiB. Video content then says so when it is opened; still images, models and the player's queue are the
// same code as in the full build.
#include "projbot/assets/video.hpp"

namespace projbot::assets {
namespace {

[[noreturn]] void left_out(const std::string& what) {
  throw AssetError(what + ": video needs FFmpeg, which this portable build leaves out (tools/bundle.sh): use the full build");
}

}  // namespace

struct VideoDecoder::Impl {
  VideoInfo info;
  std::string name;
};
VideoDecoder::VideoDecoder(const std::filesystem::path& path) { left_out(path.string()); }
VideoDecoder::VideoDecoder(std::span<const std::uint8_t>, std::string name) { left_out(name); }
VideoDecoder::~VideoDecoder() = default;
const VideoInfo& VideoDecoder::info() const { return impl_->info; }
const std::string& VideoDecoder::name() const { return impl_->name; }
bool VideoDecoder::next(VideoFrame&) { return false; }
void VideoDecoder::rewind() {}
void VideoDecoder::seek(double) {}
void VideoDecoder::check_first_frame() {}

struct VideoWriter::Impl {};
VideoWriter::VideoWriter(const std::filesystem::path& path, int, int, int, const std::string&) { left_out(path.string()); }
VideoWriter::~VideoWriter() = default;
void VideoWriter::write(const Image&) {}
void VideoWriter::finish() {}

}  // namespace projbot::assets
