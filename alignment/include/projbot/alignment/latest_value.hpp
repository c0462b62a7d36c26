#pragma once
// The hand-off between one writer thread and one reader thread: the reader always gets the newest
// complete value, neither side ever waits for the other, and stale values are simply overwritten.
// A triple buffer: the writer owns one slot, the reader one, and the third is swapped atomically.

#include <atomic>
#include <cstdint>

namespace projbot::alignment {

template <typename T>
class LatestValue {
 public:
  /// Writer thread only. Never blocks.
  void publish(const T& value) {
    slots_[back_] = value;
    back_ = middle_.exchange(static_cast<std::uint8_t>(back_ | kFresh), std::memory_order_acq_rel) & kIndex;
  }

  /// Reader thread only. Never blocks. Copies the newest published value into `out`; false (and `out`
  /// untouched) until the first publish.
  bool read(T& out) {
    if (middle_.load(std::memory_order_relaxed) & kFresh) {
      front_ = middle_.exchange(front_, std::memory_order_acq_rel) & kIndex;
      has_value_ = true;
    }
    if (!has_value_) return false;
    out = slots_[front_];
    return true;
  }

 private:
  static constexpr std::uint8_t kIndex = 0x3;
  static constexpr std::uint8_t kFresh = 0x4;
  T slots_[3]{};
  std::uint8_t back_ = 0;                // writer's slot
  std::atomic<std::uint8_t> middle_{1};  // the swap slot, with a fresh flag
  std::uint8_t front_ = 2;               // reader's slot
  bool has_value_ = false;               // reader's
};

}  // namespace projbot::alignment
