// Video decoding and encoding through FFmpeg's libraries; the player's decoder thread.
#include "projbot/assets/video.hpp"

#include "ffmpeg_util.hpp"

extern "C" {
#include <libavcodec/avcodec.h>
#include <libavformat/avformat.h>
#include <libavutil/error.h>
#include <libavutil/imgutils.h>
#include <libavutil/opt.h>
#include <libswscale/swscale.h>
}

#include <algorithm>
#include <cmath>
#include <cstring>
#include <system_error>

namespace projbot::assets {
namespace {

struct FormatCloser {
  void operator()(AVFormatContext* f) const { avformat_close_input(&f); }
};
struct CodecFreer {
  void operator()(AVCodecContext* c) const { avcodec_free_context(&c); }
};
struct FrameFreer {
  void operator()(AVFrame* f) const { av_frame_free(&f); }
};
struct PacketFreer {
  void operator()(AVPacket* p) const { av_packet_free(&p); }
};
struct SwsFreer {
  void operator()(SwsContext* s) const { sws_freeContext(s); }
};
struct IoFreer {  // a custom AVIOContext and its buffer
  void operator()(AVIOContext* io) const {
    if (io == nullptr) return;
    av_freep(&io->buffer);
    avio_context_free(&io);
  }
};

// Bytes in memory read through a custom AVIOContext.
struct MemoryInput {
  std::vector<std::uint8_t> bytes;
  std::int64_t at = 0;

  static int read(void* opaque, std::uint8_t* buf, int size) {
    auto* m = static_cast<MemoryInput*>(opaque);
    const std::int64_t left = static_cast<std::int64_t>(m->bytes.size()) - m->at;
    if (left <= 0) return AVERROR_EOF;
    const int n = static_cast<int>(std::min<std::int64_t>(left, size));
    std::memcpy(buf, m->bytes.data() + m->at, static_cast<std::size_t>(n));
    m->at += n;
    return n;
  }
  static std::int64_t seek(void* opaque, std::int64_t offset, int whence) {
    auto* m = static_cast<MemoryInput*>(opaque);
    const auto size = static_cast<std::int64_t>(m->bytes.size());
    if ((whence & AVSEEK_SIZE) != 0) return size;
    const std::int64_t base = (whence & 3) == SEEK_CUR ? m->at : (whence & 3) == SEEK_END ? size : 0;
    const std::int64_t to = base + offset;
    if (to < 0 || to > size) return AVERROR(EINVAL);
    m->at = to;
    return to;
  }
};

using detail::av_message;

// FFmpeg's own log is quiet, and no single block it allocates may exceed 256 MiB: a container's header
// claims table sizes (a fuzzed mp4 had the mov demuxer ask for 713 MB before reading a byte of them); a
// frame within the size limits needs at most 128 MiB.
void set_up_ffmpeg() {
  static const bool done = [] {
    detail::quiet_ffmpeg();
    av_max_alloc(std::size_t{256} << 20);
    return true;
  }();
  (void)done;
}

}  // namespace

struct VideoDecoder::Impl {
  std::string name;
  VideoInfo info;
  std::unique_ptr<MemoryInput> memory;
  std::unique_ptr<AVIOContext, IoFreer> io;
  std::unique_ptr<AVFormatContext, FormatCloser> format;
  std::unique_ptr<AVCodecContext, CodecFreer> codec;
  std::unique_ptr<AVFrame, FrameFreer> frame{av_frame_alloc()};
  std::unique_ptr<AVPacket, PacketFreer> packet{av_packet_alloc()};
  std::unique_ptr<SwsContext, SwsFreer> sws;
  int stream = -1;
  AVRational time_base{1, 1};
  std::int64_t first_pts = AV_NOPTS_VALUE;
  std::int64_t decoded = 0;
  bool draining = false;
  double seek_to_s = -1.0;  // after a seek: frames whose time has passed by then are decoded and dropped
  // MPEG-TS and PS: their timestamp seek is a search that can land a key frame late (back to the start it
  // skipped the first second of a clip), so they go back by byte, to the start, and decode up to a time.
  bool seeks_by_byte = false;

  [[noreturn]] void fail(const std::string& what) const { throw AssetError(name + ": " + what); }

  // What FFmpeg logged when it failed with `code`, else the code's words; a picture it refuses as too
  // large is told with this player's limits.
  std::string ffmpeg_reason(int code) const {
    const std::string said = detail::take_ffmpeg_error();
    if (said.empty()) return av_message(code);
    if (said.rfind("Picture size", 0) == 0)
      return said + "; this player takes at most " + std::to_string(kMaxSide) + " px a side and " +
             std::to_string(kMaxPixels / 1000000) + " Mpx";
    return said;
  }

  void open(AVFormatContext* ctx, const char* url) {
    AVFormatContext* raw = ctx;
    detail::take_ffmpeg_error();
    if (const int r = avformat_open_input(&raw, url, nullptr, nullptr); r < 0)
      fail("not a video FFmpeg can read (" + ffmpeg_reason(r) + ")");  // avformat_open_input freed raw
    format.reset(raw);
    if (const int r = avformat_find_stream_info(format.get(), nullptr); r < 0)
      fail("cannot read its streams (" + ffmpeg_reason(r) + ")");
    const int flags = format->iformat->flags;
    seeks_by_byte = (flags & AVFMT_TS_DISCONT) != 0 && (flags & AVFMT_NO_BYTE_SEEK) == 0;
    const AVCodec* decoder = nullptr;
    stream = av_find_best_stream(format.get(), AVMEDIA_TYPE_VIDEO, -1, -1, &decoder, 0);
    if (stream == AVERROR_STREAM_NOT_FOUND) fail("holds no video stream");
    if (stream < 0 || decoder == nullptr) {
      const AVCodecParameters* p = stream >= 0 ? format->streams[stream]->codecpar : nullptr;
      fail("its video codec (" + std::string(p ? avcodec_get_name(p->codec_id) : "unknown") + ") has no decoder in this FFmpeg");
    }
    const AVStream* s = format->streams[stream];
    check_size(s->codecpar->width, s->codecpar->height);
    open_codec(decoder, s);
    info.codec = decoder->name;
    const AVRational rate = s->avg_frame_rate.num > 0 && s->avg_frame_rate.den > 0 ? s->avg_frame_rate : s->r_frame_rate;
    info.fps = rate.num > 0 && rate.den > 0 ? av_q2d(rate) : 0.0;
    if (!(info.fps > 0.0 && info.fps <= 1000.0)) info.fps = 30.0;  // no usable rate: durations fall back to 30 fps
    if (s->duration > 0)
      info.duration_s = static_cast<double>(s->duration) * av_q2d(s->time_base);
    else if (format->duration > 0)
      info.duration_s = static_cast<double>(format->duration) / AV_TIME_BASE;
  }

  void check_size(int w, int h) const {
    if (w <= 0 || h <= 0) fail("its video stream has no size (" + std::to_string(w) + "x" + std::to_string(h) + ")");
    if (w > kMaxSide || h > kMaxSide || static_cast<std::int64_t>(w) * h > kMaxPixels)
      fail("its video is " + std::to_string(w) + "x" + std::to_string(h) + ", more than the " + std::to_string(kMaxSide) +
           " px a side and " + std::to_string(kMaxPixels / 1000000) + " Mpx this player takes");
  }

  void open_codec(const AVCodec* decoder, const AVStream* s) {
    codec.reset(avcodec_alloc_context3(decoder));
    if (!codec) fail("out of memory opening its decoder");
    if (avcodec_parameters_to_context(codec.get(), s->codecpar) < 0) fail("its codec parameters are unusable");
    codec->thread_count = 1;  // the player's thread decodes; lavapipe and the tracker have the other cores
    av_opt_set_int(codec.get(), "max_pixels", kMaxPixels, 0);
    time_base = s->time_base;
    if (const int r = avcodec_open2(codec.get(), decoder, nullptr); r < 0)
      fail("its decoder " + std::string(decoder->name) + " does not open (" + av_message(r) + ")");
  }

  // The next decoded AVFrame, or false at the end of the stream.
  bool decode_one() {
    while (true) {
      const int r = avcodec_receive_frame(codec.get(), frame.get());
      if (r == 0) return true;
      if (r == AVERROR_EOF) return false;
      if (r != AVERROR(EAGAIN)) fail("a frame does not decode (" + av_message(r) + ")");
      if (draining) return false;
      feed_packet();
    }
  }

  void feed_packet() {
    while (true) {
      const int r = av_read_frame(format.get(), packet.get());
      if (r < 0) {  // the end of the file (or a read error, treated as its end): drain the decoder
        draining = true;
        avcodec_send_packet(codec.get(), nullptr);
        return;
      }
      const bool ours = packet->stream_index == stream;
      const int sent = ours ? avcodec_send_packet(codec.get(), packet.get()) : 0;
      av_packet_unref(packet.get());
      if (sent < 0 && sent != AVERROR(EAGAIN)) fail("a packet does not decode (" + av_message(sent) + ")");
      if (ours) return;
    }
  }

  void convert(VideoFrame& out) {
    const AVFrame* f = frame.get();
    check_size(f->width, f->height);
    if (f->width != info.width || f->height != info.height)
      fail("its frames change size mid-stream (" + std::to_string(info.width) + "x" + std::to_string(info.height) + " to " +
           std::to_string(f->width) + "x" + std::to_string(f->height) + ")");
    sws.reset(sws_getCachedContext(sws.release(), f->width, f->height, static_cast<AVPixelFormat>(f->format), f->width, f->height,
                                   AV_PIX_FMT_RGBA, SWS_BILINEAR, nullptr, nullptr, nullptr));
    if (!sws) fail("its pixel format cannot be converted to RGBA");
    out.image.width = f->width;
    out.image.height = f->height;
    const std::size_t bytes = static_cast<std::size_t>(f->width) * f->height * 4;
    std::uint8_t* to = nullptr;
    if (out.pixels.data != nullptr && out.pixels.size >= bytes) {
      to = out.pixels.data;
      out.image.rgba.clear();
    } else {
      out.pixels = {};
      out.image.rgba.resize(bytes);
      to = out.image.rgba.data();
    }
    std::uint8_t* dst[4] = {to, nullptr, nullptr, nullptr};
    const int dst_stride[4] = {f->width * 4, 0, 0, 0};
    sws_scale(sws.get(), f->data, f->linesize, 0, f->height, dst, dst_stride);
  }

  // The decoded frame's duration: its packet's, else one frame period.
  double frame_duration_s() const {
    return frame->pkt_duration > 0 ? static_cast<double>(frame->pkt_duration) * av_q2d(time_base) : 1.0 / info.fps;
  }
  // The decoded frame's presentation time after the stream's first, or NaN where it has none.
  double frame_time_s() const {
    const std::int64_t pts = frame->best_effort_timestamp;
    if (pts == AV_NOPTS_VALUE || first_pts == AV_NOPTS_VALUE) return std::nan("");
    return static_cast<double>(pts - first_pts) * av_q2d(time_base);
  }

  void stamp(VideoFrame& out) {
    if (first_pts == AV_NOPTS_VALUE) first_pts = frame->best_effort_timestamp;  // stays unknown without one
    const double t = frame_time_s();
    out.duration_s = frame_duration_s();
    out.pts_s = std::isnan(t) ? static_cast<double>(decoded) / info.fps : t;
    out.index = decoded++;
  }
};

VideoDecoder::VideoDecoder(const std::filesystem::path& path) : impl_(std::make_unique<Impl>()) {
  set_up_ffmpeg();
  impl_->name = path.string();
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) impl_->fail("does not exist");
  if (!std::filesystem::is_regular_file(path, ec)) impl_->fail("is not a regular file");
  impl_->open(nullptr, path.c_str());
  check_first_frame();
}

void VideoDecoder::check_first_frame() {
  VideoFrame first;
  if (!next(first)) impl_->fail("holds no video frame that decodes (a zero-length stream)");
  rewind();
}

VideoDecoder::VideoDecoder(std::span<const std::uint8_t> bytes, std::string name) : impl_(std::make_unique<Impl>()) {
  set_up_ffmpeg();
  impl_->name = std::move(name);
  impl_->memory = std::make_unique<MemoryInput>();
  impl_->memory->bytes.assign(bytes.begin(), bytes.end());
  constexpr int kBuffer = 1 << 16;
  auto* buffer = static_cast<unsigned char*>(av_malloc(kBuffer));
  if (buffer == nullptr) impl_->fail("out of memory");
  impl_->io.reset(avio_alloc_context(buffer, kBuffer, 0, impl_->memory.get(), &MemoryInput::read, nullptr, &MemoryInput::seek));
  if (!impl_->io) {
    av_free(buffer);
    impl_->fail("out of memory");
  }
  AVFormatContext* ctx = avformat_alloc_context();
  if (ctx == nullptr) impl_->fail("out of memory");
  ctx->pb = impl_->io.get();
  ctx->flags |= AVFMT_FLAG_CUSTOM_IO;
  impl_->open(ctx, nullptr);
  check_first_frame();
}

VideoDecoder::~VideoDecoder() = default;
const VideoInfo& VideoDecoder::info() const { return impl_->info; }
const std::string& VideoDecoder::name() const { return impl_->name; }

bool VideoDecoder::next(VideoFrame& out) {
  Impl& d = *impl_;
  if (!d.decode_one()) return false;
  while (d.seek_to_s > 0.0) {  // after a seek: decoded from the key frame before, kept from the frame showing then
    const double t = d.frame_time_s();
    if (std::isnan(t) || t + d.frame_duration_s() > d.seek_to_s + 1e-6) break;
    av_frame_unref(d.frame.get());
    ++d.decoded;
    if (!d.decode_one()) return false;
  }
  d.seek_to_s = -1.0;
  if (d.info.width == 0) {  // the first frame fixes the size every later one must keep
    d.check_size(d.frame->width, d.frame->height);
    d.info.width = d.frame->width;
    d.info.height = d.frame->height;
  }
  d.convert(out);
  d.stamp(out);
  av_frame_unref(d.frame.get());
  return true;
}

void VideoDecoder::seek(double t_s) {
  Impl& d = *impl_;
  if (!(t_s > 0.0) || d.first_pts == AV_NOPTS_VALUE) {
    rewind();
    return;
  }
  if (d.seeks_by_byte) {  // decoded from the start, dropped up to the time: slower, never a frame late
    rewind();
    d.seek_to_s = t_s;
    return;
  }
  const auto ts = d.first_pts + static_cast<std::int64_t>(t_s / av_q2d(d.time_base));
  if (av_seek_frame(d.format.get(), d.stream, ts, AVSEEK_FLAG_BACKWARD) < 0) {
    rewind();  // a container that cannot seek: decoded from the start, dropped up to the time
  } else {
    avcodec_flush_buffers(d.codec.get());
    d.draining = false;
    d.decoded = 0;
  }
  d.seek_to_s = t_s;
}

void VideoDecoder::rewind() {
  Impl& d = *impl_;
  const std::int64_t start = d.format->streams[d.stream]->start_time;
  const int r = d.seeks_by_byte
                    ? av_seek_frame(d.format.get(), d.stream, 0, AVSEEK_FLAG_BYTE)
                    : av_seek_frame(d.format.get(), d.stream, start == AV_NOPTS_VALUE ? 0 : start, AVSEEK_FLAG_BACKWARD);
  if (r < 0 && avformat_seek_file(d.format.get(), -1, INT64_MIN, 0, INT64_MAX, 0) < 0)
    d.fail("cannot go back to its first frame (" + av_message(r) + ")");
  avcodec_flush_buffers(d.codec.get());
  d.draining = false;
  d.decoded = 0;
  d.seek_to_s = -1.0;
}

}  // namespace projbot::assets
