#pragma once
// Per-frame timing: CPU timestamps of each stage and GPU time, with a percentile summary.
// Owned and called by the render thread only.

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace projbot::engine {

/// One frame's timeline, milliseconds since the profiler started (NaN where not measured).
struct FrameRecord {
  std::uint64_t index = 0;
  double start_ms = 0.0;      ///< frame begins (before waiting for its frame slot)
  double pose_read_ms = 0.0;  ///< poses read for this frame
  double recorded_ms = 0.0;   ///< command buffer recorded
  double submitted_ms = 0.0;  ///< queue submit returned
  double presented_ms = 0.0;  ///< present returned (swapchain) or = submitted (offscreen)
  double completed_ms = 0.0;  ///< the frame's fence was seen signalled
  double gpu_ms = 0.0;        ///< GPU time from timestamp queries, NaN if the device has none
  double upload_ms = 0.0;     ///< render-thread time copying streamed texels (video) into staging memory; 0: none this frame
};

/// Percentiles of frame time (start to next start) and GPU time, milliseconds.
struct FrameSummary {
  std::size_t frames = 0;
  double p50_ms = 0, p95_ms = 0, p99_ms = 0, max_ms = 0, mean_ms = 0;
  double fps = 0;                               ///< frames / wall time from first start to last completion
  double gpu_p50_ms = 0, gpu_p99_ms = 0;        ///< NaN without timestamp queries
  double cpu_record_p50_ms = 0;                 ///< pose read to command buffer recorded
  std::size_t uploads = 0;                      ///< frames that uploaded streamed texels (video)
  double upload_p50_ms = 0, upload_p99_ms = 0;  ///< over those frames; NaN where frames were drawn but none uploaded
};

class FrameProfiler {
 public:
  FrameProfiler();
  /// Milliseconds since construction, steady clock.
  double now_ms() const;
  void add(const FrameRecord& record);
  const std::vector<FrameRecord>& records() const { return records_; }
  FrameSummary summary() const;
  /// One row per frame; throws std::runtime_error if the file cannot be written.
  void write_csv(const std::filesystem::path& path) const;

 private:
  std::chrono::steady_clock::time_point t0_;
  std::vector<FrameRecord> records_;
};

/// "120 frames, 59.8 fps; frame time p50 16.6 ms, p95 ..., gpu p50 ..." for people.
std::string format_summary(const FrameSummary& summary);

/// The q-quantile (0..1) of values by linear interpolation; NaN for an empty list.
double percentile(std::vector<double> values, double q);

}  // namespace projbot::engine
