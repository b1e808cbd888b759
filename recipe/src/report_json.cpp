// The one JSON form of a step's report (report_json.hpp).
#include "report_json.hpp"

#include <variant>

namespace clay::recipe {

namespace detail {

ReportJson figure_json(const Figure& figure) {
  return std::visit([](const auto& x) { return ReportJson(x); }, figure);
}

ReportJson figures_json(const StepReport* step) {
  ReportJson j = ReportJson::object();
  if (step)
    for (const auto& [name, value] : step->figures) j[name] = figure_json(value);
  return j;
}

ReportJson step_json(const StepReport& step) {
  ReportJson x = ReportJson::object();
  x["path"] = step.path;
  x["kind"] = step.kind;
  x["seconds"] = step.seconds;
  x["warning"] = step.warning;
  if (step.reused) x["reused"] = true;  // taken from an earlier run (RunCache, previous)
  x["message"] = step.message;
  x["figures"] = figures_json(&step);
  return x;
}

ReportJson continuity_json(const brep::ContinuityReport& before,
                           const brep::ContinuityReport& after) {
  using Json = ReportJson;
  Json j = Json::object();
  j["shared_edges"] = after.edges.size();
  j["max_gap_mm"] = after.max_gap_mm;
  j["max_angle_deg"] = after.max_angle_deg;
  j["max_relative_curvature_jump"] = after.max_relative_curvature_jump;
  j["message"] = after.brief();
  j["before"] = before.brief();
  Json edges = Json::array();
  for (std::size_t k = 0; k < after.edges.size(); ++k) {
    const brep::EdgeContinuity& e = after.edges[k];
    Json x = Json::object();
    x["edge"] = e.edge;
    x["faces"] = Json::array({e.face_a, e.face_b});
    x["gap_mm"] = e.gap_mm;
    x["angle_deg"] = e.angle_deg;
    x["curvature_jump"] = e.curvature_jump;
    x["relative_curvature_jump"] = e.relative_curvature_jump;
    if (k < before.edges.size() && before.edges[k].edge == e.edge) {
      const brep::EdgeContinuity& b = before.edges[k];
      x["class"] = b.angle_deg <= 1 ? (b.relative_curvature_jump <= 0.05 ? "G2" : "G1") : "G0";
      x["before"] = Json{{"gap_mm", b.gap_mm},
                         {"angle_deg", b.angle_deg},
                         {"relative_curvature_jump", b.relative_curvature_jump}};
    }
    edges.push_back(std::move(x));
  }
  j["edges"] = std::move(edges);
  return j;
}

}  // namespace detail

std::string step_reports_json(const std::vector<StepReport>& steps) {
  detail::ReportJson list = detail::ReportJson::array();
  for (const StepReport& s : steps) list.push_back(detail::step_json(s));
  return list.dump(-1, ' ', false, detail::ReportJson::error_handler_t::replace);
}

}  // namespace clay::recipe
