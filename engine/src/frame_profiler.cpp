#include "projbot/engine/frame_profiler.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <stdexcept>

#include "projbot/config/clock.hpp"
#include "projbot/config/output_file.hpp"

namespace projbot::engine {

FrameProfiler::FrameProfiler() : t0_(std::chrono::steady_clock::now()) {}

double FrameProfiler::now_ms() const { return config::ms_since(t0_); }

void FrameProfiler::add(const FrameRecord& record) { records_.push_back(record); }

double percentile(std::vector<double> values, double q) {
  std::erase_if(values, [](double v) { return std::isnan(v); });
  if (values.empty()) return std::nan("");
  // The two order statistics it needs, without sorting all (millions of pixels in bench sensor).
  const double pos = std::clamp(q, 0.0, 1.0) * static_cast<double>(values.size() - 1);
  const auto lo = static_cast<std::size_t>(std::floor(pos));
  const auto at = values.begin() + static_cast<std::ptrdiff_t>(lo);
  std::nth_element(values.begin(), at, values.end());
  if (lo + 1 >= values.size()) return *at;
  const double next = *std::min_element(at + 1, values.end());
  return *at + (pos - static_cast<double>(lo)) * (next - *at);
}

FrameSummary FrameProfiler::summary() const {
  FrameSummary s;
  s.frames = records_.size();
  if (records_.empty()) return s;
  std::vector<FrameRecord> r = records_;
  std::sort(r.begin(), r.end(), [](const auto& a, const auto& b) { return a.index < b.index; });
  // Frame time: from one frame's start to the next one's; the last frame ends when its fence signals.
  std::vector<double> frame, gpu, record, upload;
  for (std::size_t i = 0; i < r.size(); ++i) {
    frame.push_back((i + 1 < r.size() ? r[i + 1].start_ms : r[i].completed_ms) - r[i].start_ms);
    gpu.push_back(r[i].gpu_ms);
    record.push_back(r[i].recorded_ms - r[i].pose_read_ms);
    if (r[i].upload_ms > 0.0) upload.push_back(r[i].upload_ms);
  }
  s.uploads = upload.size();
  s.upload_p50_ms = percentile(upload, 0.50);
  s.upload_p99_ms = percentile(upload, 0.99);
  s.p50_ms = percentile(frame, 0.50);
  s.p95_ms = percentile(frame, 0.95);
  s.p99_ms = percentile(frame, 0.99);
  s.max_ms = *std::max_element(frame.begin(), frame.end());
  double sum = 0;
  for (double f : frame) sum += f;
  s.mean_ms = sum / static_cast<double>(frame.size());
  const double wall = r.back().completed_ms - r.front().start_ms;
  s.fps = wall > 0 ? static_cast<double>(r.size()) * 1000.0 / wall : 0.0;
  s.gpu_p50_ms = percentile(gpu, 0.50);
  s.gpu_p99_ms = percentile(gpu, 0.99);
  s.cpu_record_p50_ms = percentile(record, 0.50);
  return s;
}

void FrameProfiler::write_csv(const std::filesystem::path& path) const {
  std::string out = "frame,start_ms,pose_read_ms,recorded_ms,submitted_ms,presented_ms,completed_ms,frame_ms,gpu_ms\n";
  for (std::size_t i = 0; i < records_.size(); ++i) {
    const auto& r = records_[i];
    const double frame = (i + 1 < records_.size() ? records_[i + 1].start_ms : r.completed_ms) - r.start_ms;
    char line[256];
    std::snprintf(line, sizeof line, "%llu,%.4f,%.4f,%.4f,%.4f,%.4f,%.4f,%.4f,%.4f\n", static_cast<unsigned long long>(r.index),
                  r.start_ms, r.pose_read_ms, r.recorded_ms, r.submitted_ms, r.presented_ms, r.completed_ms, frame, r.gpu_ms);
    out += line;
  }
  config::write_file_atomically(path, out);
}

std::string format_summary(const FrameSummary& s) {
  char buf[512];
  std::snprintf(buf, sizeof buf,
                "%zu frames, %.1f fps; frame time p50 %.2f ms, p95 %.2f ms, p99 %.2f ms, max %.2f ms; "
                "gpu p50 %.2f ms, p99 %.2f ms; cpu record p50 %.3f ms",
                s.frames, s.fps, s.p50_ms, s.p95_ms, s.p99_ms, s.max_ms, s.gpu_p50_ms, s.gpu_p99_ms, s.cpu_record_p50_ms);
  return buf;
}

}  // namespace projbot::engine
