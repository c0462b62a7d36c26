// Encoding RGBA8 frames to a video file through FFmpeg's libraries.
#include <algorithm>
#include <cmath>
#include <system_error>

#include "ffmpeg_util.hpp"
#include "projbot/assets/video.hpp"

extern "C" {
#include <libavcodec/avcodec.h>
#include <libavformat/avformat.h>
#include <libavutil/error.h>
#include <libavutil/opt.h>
#include <libswscale/swscale.h>
}

namespace projbot::assets {

struct VideoWriter::Impl {
  std::filesystem::path path, temporary;
  AVFormatContext* format = nullptr;
  AVCodecContext* codec = nullptr;
  AVStream* stream = nullptr;
  AVFrame* frame = nullptr;
  AVPacket* packet = nullptr;
  SwsContext* sws = nullptr;
  std::int64_t next_pts = 0;
  bool opened_file = false, done = false;

  [[noreturn]] void fail(const std::string& what) const { throw AssetError(path.string() + ": " + what); }
  void check(int r, const char* what) const {
    if (r < 0) fail(std::string(what) + " (" + detail::av_message(r) + ")");
  }

  void release() noexcept {
    sws_freeContext(sws);
    sws = nullptr;
    av_packet_free(&packet);
    av_frame_free(&frame);
    avcodec_free_context(&codec);
    if (format != nullptr && opened_file) avio_closep(&format->pb);
    avformat_free_context(format);
    format = nullptr;
  }

  static AVPixelFormat pixel_format(const AVCodec* c) {
    if (c->pix_fmts == nullptr) return AV_PIX_FMT_YUV420P;
    for (const AVPixelFormat* p = c->pix_fmts; *p != AV_PIX_FMT_NONE; ++p)  // what every player plays
      if (*p == AV_PIX_FMT_YUV420P && c->id != AV_CODEC_ID_FFV1) return *p;
    return avcodec_find_best_pix_fmt_of_list(c->pix_fmts, AV_PIX_FMT_RGBA, 0, nullptr);
  }

  void open_codec(const std::string& name, int width, int height, int fps) {
    const AVCodec* c = avcodec_find_encoder_by_name(name.c_str());
    if (c == nullptr) fail("this FFmpeg has no encoder named " + name);
    stream = avformat_new_stream(format, nullptr);
    codec = avcodec_alloc_context3(c);
    if (stream == nullptr || codec == nullptr) fail("out of memory");
    codec->width = width;
    codec->height = height;
    codec->time_base = AVRational{1, fps};
    codec->framerate = AVRational{fps, 1};
    codec->gop_size = fps;
    codec->pix_fmt = pixel_format(c);
    if ((format->oformat->flags & AVFMT_GLOBALHEADER) != 0) codec->flags |= AV_CODEC_FLAG_GLOBAL_HEADER;
    if (c->id == AV_CODEC_ID_H264) {
      av_opt_set(codec->priv_data, "preset", "veryfast", 0);
      av_opt_set(codec->priv_data, "crf", "18", 0);
    }
    check(avcodec_open2(codec, c, nullptr), "the encoder does not open");
    check(avcodec_parameters_from_context(stream->codecpar, codec), "the stream parameters");
    stream->time_base = codec->time_base;
    frame = av_frame_alloc();
    packet = av_packet_alloc();
    if (frame == nullptr || packet == nullptr) fail("out of memory");
    frame->format = codec->pix_fmt;
    frame->width = width;
    frame->height = height;
    check(av_frame_get_buffer(frame, 0), "no memory for a frame");
    sws = sws_getContext(width, height, AV_PIX_FMT_RGBA, width, height, codec->pix_fmt, SWS_BICUBIC, nullptr, nullptr, nullptr);
    if (sws == nullptr) fail("RGBA cannot be converted to the encoder's pixel format");
  }

  void drain(bool flush) {
    if (flush) check(avcodec_send_frame(codec, nullptr), "the encoder does not flush");
    while (true) {
      const int r = avcodec_receive_packet(codec, packet);
      if (r == AVERROR(EAGAIN) || r == AVERROR_EOF) return;
      check(r, "the encoder failed");
      if (packet->duration <= 0) packet->duration = 1;  // one frame: else mp4's edit list cuts the last one off
      av_packet_rescale_ts(packet, codec->time_base, stream->time_base);
      packet->stream_index = stream->index;
      check(av_interleaved_write_frame(format, packet), "writing failed");
    }
  }
};

VideoWriter::VideoWriter(const std::filesystem::path& path, int width, int height, int fps, const std::string& codec)
    : impl_(std::make_unique<Impl>()) {
  detail::quiet_ffmpeg();
  Impl& w = *impl_;
  w.path = path;
  if (width <= 0 || height <= 0 || width > 16384 || height > 16384 || fps <= 0 || fps > 1000)
    w.fail("a video of " + std::to_string(width) + "x" + std::to_string(height) + " at " + std::to_string(fps) +
           " fps cannot be written");
  const AVOutputFormat* of = av_guess_format(nullptr, path.filename().c_str(), nullptr);
  if (of == nullptr) w.fail("no container FFmpeg writes has this file's extension");
  w.temporary = path;
  w.temporary += ".partial";
  try {
    w.check(avformat_alloc_output_context2(&w.format, of, nullptr, w.temporary.c_str()), "the container does not open");
    w.open_codec(codec, width, height, fps);
    w.check(avio_open(&w.format->pb, w.temporary.c_str(), AVIO_FLAG_WRITE), "cannot be written");
    w.opened_file = true;
    w.check(avformat_write_header(w.format, nullptr), "the container header");
  } catch (...) {
    w.release();
    std::error_code ec;
    std::filesystem::remove(w.temporary, ec);
    throw;
  }
}

VideoWriter::~VideoWriter() {
  if (!impl_) return;
  impl_->release();
  if (!impl_->done) {
    std::error_code ec;
    std::filesystem::remove(impl_->temporary, ec);
  }
}

void VideoWriter::write(const Image& image) {
  Impl& w = *impl_;
  if (w.done) w.fail("write after finish");
  if (image.width != w.codec->width || image.height != w.codec->height ||
      image.rgba.size() != static_cast<std::size_t>(image.width) * image.height * 4)
    w.fail("a frame of " + std::to_string(image.width) + "x" + std::to_string(image.height) + " in a " +
           std::to_string(w.codec->width) + "x" + std::to_string(w.codec->height) + " video");
  w.check(av_frame_make_writable(w.frame), "no writable frame");
  const std::uint8_t* src[4] = {image.rgba.data(), nullptr, nullptr, nullptr};
  const int stride[4] = {image.width * 4, 0, 0, 0};
  sws_scale(w.sws, src, stride, 0, image.height, w.frame->data, w.frame->linesize);
  w.frame->pts = w.next_pts++;
  w.check(avcodec_send_frame(w.codec, w.frame), "the encoder refused a frame");
  w.drain(false);
}

void VideoWriter::finish() {
  Impl& w = *impl_;
  if (w.done) return;
  w.drain(true);
  w.check(av_write_trailer(w.format), "the container trailer");
  w.release();
  std::error_code ec;
  std::filesystem::rename(w.temporary, w.path, ec);
  if (ec) w.fail("cannot be put in place (" + ec.message() + ")");
  w.done = true;
}

}  // namespace projbot::assets
