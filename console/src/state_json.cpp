// The show's state as the console's API gives it.

#include <nlohmann/json.hpp>

#include "projbot/console/console.hpp"

namespace projbot::console {

std::string state_json(const live::ShowState& s) {
  nlohmann::json targets = nlohmann::json::array();
  for (const live::TargetShowState& t : s.targets) {
    nlohmann::json j{{"name", t.name}, {"state", t.state}, {"visited", t.visited}};
    j["error_mm"] = t.error_mm >= 0.0 ? nlohmann::json(t.error_mm) : nlohmann::json(nullptr);
    j["at"] = t.at ? nlohmann::json{{"x_m", (*t.at)[0]}, {"y_m", (*t.at)[1]}} : nlohmann::json(nullptr);
    j["content"] = t.content.empty() ? nlohmann::json(nullptr) : nlohmann::json(t.content);
    targets.push_back(std::move(j));
  }
  nlohmann::json stops = nlohmann::json::array();
  for (const auto& p : s.stops) stops.push_back({{"x_m", p[0]}, {"y_m", p[1]}, {"heading_rad", p[2]}});
  nlohmann::json tour = nlohmann::json::array();
  const auto mm = [](double v) { return v >= 0.0 ? nlohmann::json(v) : nlohmann::json(nullptr); };
  for (const live::VisitShowRow& r : s.tour)
    tour.push_back({{"visit", r.visit},
                    {"target", r.target},
                    {"frames", r.frames},
                    {"lit_frames", r.lit_frames},
                    {"mean_mm", mm(r.mean_mm)},
                    {"worst_mm", mm(r.worst_mm)}});
  const nlohmann::json robot =
      s.robot ? nlohmann::json{{"x_m", (*s.robot)[0]}, {"y_m", (*s.robot)[1]}, {"heading_rad", (*s.robot)[2]}}
              : nlohmann::json(nullptr);
  return nlohmann::json{{"sequence", s.sequence},
                        {"clock_s", s.clock_s},
                        {"phase", s.phase},
                        {"visit", s.visit},
                        {"visiting", s.visiting.empty() ? nlohmann::json(nullptr) : nlohmann::json(s.visiting)},
                        {"robot", robot},
                        {"stops", stops},
                        {"targets", targets},
                        {"frame_rate_hz", s.frame_rate_hz},
                        {"pose_age_ms", s.pose_age_ms >= 0.0 ? nlohmann::json(s.pose_age_ms) : nlohmann::json(nullptr)},
                        {"blackout", s.blackout},
                        {"paused", s.paused},
                        {"go_to", s.go_to.empty() ? nlohmann::json(nullptr) : nlohmann::json(s.go_to)},
                        {"tour", tour}}
      .dump();
}

}  // namespace projbot::console
