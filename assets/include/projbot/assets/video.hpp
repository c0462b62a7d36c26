#pragma once
// Content that moves (issue 44): video files decoded with FFmpeg's libraries (libavformat, libavcodec,
// libswscale) into RGBA8 frames with their presentation times; a player that decodes on its own thread
// ahead of the display clock into a small bounded queue and hands the render thread, without waiting,
// the frame of a content time; a writer (tests and the shipped sample make their clips with it).

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <filesystem>
#include <functional>
#include <memory>
#include <mutex>
#include <span>
#include <string>
#include <thread>
#include <vector>

#include "projbot/assets/image.hpp"

namespace projbot::assets {

/// What a video file holds, read when it is opened.
struct VideoInfo {
  int width = 0;
  int height = 0;
  double fps = 0.0;         ///< the stream's frame rate (average where it varies)
  double duration_s = 0.0;  ///< from the container; 0 where it does not say
  std::string codec;        ///< FFmpeg's decoder name, e.g. "h264"
};

/// Memory a frame's RGBA8 pixels are decoded into when a player is given an allocator: memory its consumer
/// reads directly (the renderer's upload buffers, which the GPU copies from without a CPU copy).
struct PixelMemory {
  std::uint8_t* data = nullptr;
  std::size_t size = 0;
  std::shared_ptr<void> owner;  ///< keeps the memory alive
  const void* tag = nullptr;    ///< who made it (the consumer recognises its own)
};
using PixelAllocator = std::function<PixelMemory(std::size_t bytes)>;

/// One decoded frame.
struct VideoFrame {
  std::int64_t index = 0;   ///< decoded frames before it since the stream (re)started or a seek
  double pts_s = 0.0;       ///< presentation time, seconds after the stream's first frame (loops add on)
  double duration_s = 0.0;  ///< until the next frame's presentation time
  /// RGBA8, the video's size, alpha 255: in image.rgba, or (width and height in image, rgba empty) in
  /// `pixels` where those were given before decoding.
  Image image;
  PixelMemory pixels;
  const std::uint8_t* rgba() const { return pixels.data != nullptr ? pixels.data : image.rgba.data(); }
};

/// A video stream decoded frame by frame, in presentation order. Not thread-safe: one thread at a time.
class VideoDecoder {
 public:
  static constexpr int kMaxSide = 8192;                      ///< a larger width or height is refused
  static constexpr std::int64_t kMaxPixels = 4096LL * 4096;  ///< so is a frame of more pixels (64 MiB RGBA)

  /// Opens `path`, checks its first video stream (a decoder FFmpeg has, a size within the limits) and
  /// decodes its first frame. Throws AssetError naming the file: missing, not a container FFmpeg knows, no
  /// video stream, a codec without a decoder, an absurd size, no frame that decodes.
  explicit VideoDecoder(const std::filesystem::path& path);
  /// The same from bytes in memory (`name` for messages): the fuzz target's entry.
  VideoDecoder(std::span<const std::uint8_t> bytes, std::string name);
  ~VideoDecoder();
  VideoDecoder(const VideoDecoder&) = delete;
  VideoDecoder& operator=(const VideoDecoder&) = delete;

  const VideoInfo& info() const;
  const std::string& name() const;
  /// The next frame into `out` (its pixel buffer reused where the size matches). False at the end of the
  /// stream. Throws AssetError naming the file when a frame fails to decode.
  bool next(VideoFrame& out);
  /// Back to the first frame.
  void rewind();
  /// On to the frame presented at `t_s` seconds after the first: from the key frame before it, the frames
  /// between decoded and dropped by the next next(). A time past the end leaves nothing to decode.
  void seek(double t_s);

 private:
  void check_first_frame();  // decodes the first frame (or says there is none), then rewinds
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// What a player did, counted since it started.
struct PlaybackStats {
  std::size_t decoded = 0;   ///< frames the decoder thread produced
  std::size_t shown = 0;     ///< frames handed out for the first time
  std::size_t skipped = 0;   ///< decoded frames passed over: their time had gone when they were asked for
  std::size_t repeated = 0;  ///< asks answered with an older frame because the due one was not decoded yet
  std::size_t waits = 0;     ///< asks that waited: the queue locked by the decoder thread, or frame_due for a frame
  std::size_t loops = 0;     ///< times the stream started again from its first frame
  std::size_t seeks = 0;     ///< jumps ahead: content asked for more than a second past what was decoded
};

/// Plays a video against a content clock: a decoder thread keeps up to `queue_frames` decoded frames
/// ahead, frame_at() takes the one whose presentation time is due without waiting for the decoder.
/// Looping: the stream starts again after its last frame, its times going on (content time is not
/// wrapped). A decode error during playback stops the stream where it is: the last good frame stays, the
/// error is kept for error() and reported once.
class VideoPlayer {
 public:
  /// `allocator`: where frames are decoded into (null: their own vectors); called on the decoder thread.
  VideoPlayer(std::unique_ptr<VideoDecoder> decoder, bool loop, std::size_t queue_frames = 4, PixelAllocator allocator = {});
  ~VideoPlayer();
  VideoPlayer(const VideoPlayer&) = delete;
  VideoPlayer& operator=(const VideoPlayer&) = delete;

  struct Shown {
    std::shared_ptr<const VideoFrame> frame;  ///< null until the first frame is decoded
    bool fresh = false;                       ///< a frame not handed out before: upload it
  };
  /// The frame to show at `content_s` seconds after the content began: the latest decoded one presented
  /// at or before it. Never waits for decoding (live: a late decoder repeats the frame shown). Content
  /// times before the previous ask's mean the content began again (a new arrival): the stream restarts
  /// from its first frame.
  Shown frame_at(double content_s);
  /// The same, but waits for the decoder until the frame due at `content_s` is known (a replay: the same
  /// frame every time, never a repeat), up to `timeout_s`; past it, as frame_at.
  Shown frame_due(double content_s, double timeout_s = 5.0);
  PlaybackStats stats() const;
  /// The playback error, once: empty after the first call that returned it, and while there is none.
  std::string take_error();
  const VideoInfo& info() const { return info_; }
  const std::string& name() const { return name_; }
  bool loop() const { return loop_; }

 private:
  void decode_loop(const std::stop_token& stop);
  Shown take_due(double content_s, bool count_repeat);  // frame_at's work, the mutex held
  bool due_known(double content_s) const;
  struct FramePool;
  std::shared_ptr<VideoFrame> spare_frame();  // a frame to decode into, back to the pool when let go

  std::unique_ptr<VideoDecoder> decoder_;
  PixelAllocator allocator_;
  VideoInfo info_;
  std::string name_;
  bool loop_ = true;
  std::size_t capacity_ = 4;
  mutable std::mutex mutex_;
  std::condition_variable_any wake_;
  std::deque<std::shared_ptr<VideoFrame>> queue_;  // decoded, not yet due; presentation order
  std::shared_ptr<FramePool> pool_;                // frames to decode into again
  std::shared_ptr<VideoFrame> current_;            // the frame last handed out
  bool restart_ = false, ended_ = false, error_reported_ = false;
  bool seeking_ = false;  // a jump asked for whose first frame is not queued yet
  double seek_s_ = -1.0;  // a content time the decoder thread is asked to jump to (the content ran on unseen); < 0: none
  std::string error_;
  double last_ask_s_ = 0.0;
  PlaybackStats stats_;
  std::jthread thread_;  // last: started after, and stopped before, everything above
};

/// Writes RGBA8 frames to a video file: the container from the extension (.mp4, .mkv, .avi, ...), the codec
/// by FFmpeg encoder name (libx264 by default; "ffv1" is lossless). Written to a temporary file beside
/// `path` and renamed over it by finish(): a failed or abandoned write leaves no partial file.
class VideoWriter {
 public:
  VideoWriter(const std::filesystem::path& path, int width, int height, int fps, const std::string& codec = "libx264");
  ~VideoWriter();  ///< abandons an unfinished file (removes its temporary); never throws
  VideoWriter(const VideoWriter&) = delete;
  VideoWriter& operator=(const VideoWriter&) = delete;
  /// Appends one frame of the writer's size. Throws AssetError.
  void write(const Image& frame);
  /// Flushes the encoder, closes and renames the file into place. Throws AssetError.
  void finish();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// A test pattern whose frames say their own number: the lower half is kFrameCodeBits vertical stripes,
/// white for a set bit of `index` (most significant bit at the left), black for a clear one; the upper
/// half a colour wash whose hue turns with the index (what a person sees move).
inline constexpr int kFrameCodeBits = 10;
Image frame_code_image(std::int64_t index, int width, int height);
/// The number frame_code_image drew into the region [x0, x0 + w) x [y0, y0 + h) of `image` (the whole
/// frame drawn there), read at the middle of each stripe; -1 where a stripe is neither dark nor light.
std::int64_t read_frame_code(const Image& image, int x0, int y0, int w, int h);

}  // namespace projbot::assets
