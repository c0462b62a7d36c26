#pragma once
// Acquisition from perturbed initial guesses in the twin (`projbot bench acquire`, issue 11): ours (the
// tracker's TargetFollower::acquire, its quality gate and free-space check) beside PCL's own pipeline on
// the same captures; success rate, false accepts (and those that look alike), false blanks and time.

#include <array>
#include <cstdint>
#include <functional>
#include <random>
#include <string>
#include <vector>

#include "projbot/config/scene.hpp"
#include "projbot/engine/renderer.hpp"
#include "projbot/twin/world.hpp"

namespace projbot::bench {

/// One acquisition: lit or blanked, how far its pose is from the truth (mm, degrees), how long it took (ms).
struct AcquireOutcome {
  bool lit = false;
  double error_mm = 0.0, error_deg = 0.0, ms = 0.0;
  bool looks_alike = false;  ///< lit far off, and the content it puts on the seen surfaces is the truth's
  /// Lit more than 10 mm or 2 degrees off: a false accept (a cube turned onto another face too).
  bool far_off() const { return lit && (error_mm > 10.0 || error_deg > 2.0); }
};

/// Outcomes counted. Success: lit within 3 mm and 0.5 degrees; false blank: blanked that close.
struct AcquireTally {
  int trials = 0, success = 0, false_accepts = 0, false_blanks = 0, look_alikes = 0;
  std::vector<double> ms;
  void add(const AcquireOutcome& o);
};

/// The methods, in the order of a target's tallies.
inline constexpr std::array<const char*, 3> kAcquireMethods{"ours", "PCL", "PCL, serial search"};

struct AcquireOptions {
  int trials = 20;                          ///< captures per target
  double guess_cm = 5.0, guess_deg = 10.0;  ///< the small guesses' error; the gross ones are 30 cm, 40 degrees
  std::uint64_t seed = 1;                   ///< the guesses and the depth noise
};

/// One target's tallies: [0..2] the small guesses by kAcquireMethods, [3..5] the gross ones.
struct AcquireTarget {
  std::string name;
  int trials = 0;  ///< captures done (fewer than asked when stopped)
  std::array<AcquireTally, 6> tallies;
};

class AcquireBench {
 public:
  /// The scene's twin on `renderer` (which must outlive the bench).
  AcquireBench(const config::Scene& scene, const AcquireOptions& options, engine::Renderer& renderer);
  std::size_t targets() const { return twin_.targets().size(); }
  const std::string& target_name(std::size_t index) const { return twin_.targets()[index].config.name; }
  /// Drives to target `index`'s stop, aims, and acquires from each capture's guesses; `keep_going` is asked
  /// before each capture and `trial_done` called after it with the trials finished so far.
  AcquireTarget run_target(std::size_t index, const std::function<bool()>& keep_going,
                           const std::function<void(const AcquireTarget&)>& trial_done);

 private:
  AcquireOptions options_;
  twin::Twin twin_;
  std::mt19937 rng_;
};

}  // namespace projbot::bench
