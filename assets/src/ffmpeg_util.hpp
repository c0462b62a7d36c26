#pragma once
// What the video decoder and writer share of FFmpeg's plumbing (assets-internal).

extern "C" {
#include <libavutil/error.h>
#include <libavutil/log.h>
}

#include <string>

namespace projbot::assets::detail {

/// FFmpeg's words for an error code.
inline std::string av_message(int code) {
  char text[AV_ERROR_MAX_STRING_SIZE] = {};
  av_strerror(code, text, sizeof text);
  return text;
}

/// FFmpeg's own log off: what goes wrong is one line of ours naming the file (its statistics are not for
/// people either).
inline void quiet_ffmpeg() { av_log_set_level(AV_LOG_QUIET); }

}  // namespace projbot::assets::detail
