#pragma once
// What the video decoder and writer share of FFmpeg's plumbing (assets-internal).

extern "C" {
#include <libavutil/error.h>
#include <libavutil/log.h>
}

#include <cstdarg>
#include <cstdio>
#include <string>
#include <utility>

namespace projbot::assets::detail {

/// FFmpeg's words for an error code.
inline std::string av_message(int code) {
  char text[AV_ERROR_MAX_STRING_SIZE] = {};
  av_strerror(code, text, sizeof text);
  return text;
}

/// The last error FFmpeg logged on this thread: its error codes alone can mislead ("Device or resource busy"
/// for a picture too large), its log says what it refused.
inline std::string& last_ffmpeg_error() {
  thread_local std::string said;
  return said;
}

/// last_ffmpeg_error, emptied: what FFmpeg said since the last take.
inline std::string take_ffmpeg_error() { return std::exchange(last_ffmpeg_error(), std::string()); }

/// FFmpeg's own log off the terminal: what goes wrong is one line of ours naming the file (its statistics are
/// not for people either); its errors are kept for that line (last_ffmpeg_error).
inline void quiet_ffmpeg() {
  av_log_set_callback([](void*, int level, const char* format, va_list args) {
    if (level > AV_LOG_ERROR) return;
    char line[512];
    std::vsnprintf(line, sizeof line, format, args);
    std::string& said = last_ffmpeg_error();
    said = line;
    while (!said.empty() && (said.back() == '\n' || said.back() == ' ')) said.pop_back();
  });
}

}  // namespace projbot::assets::detail
