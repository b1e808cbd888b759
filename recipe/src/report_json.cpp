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
  x["message"] = step.message;
  x["figures"] = figures_json(&step);
  return x;
}

}  // namespace detail

std::string step_reports_json(const std::vector<StepReport>& steps) {
  detail::ReportJson list = detail::ReportJson::array();
  for (const StepReport& s : steps) list.push_back(detail::step_json(s));
  return list.dump(-1, ' ', false, detail::ReportJson::error_handler_t::replace);
}

}  // namespace clay::recipe
