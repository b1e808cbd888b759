// Step figures and wording shared by the recipe runner (recipe_run.hpp).
#include <cctype>
#include <string>
#include <vector>

#include "recipe_run.hpp"

namespace clay::recipe::detail {

/// `m` with every "WORD #k" replaced by WORD "names[k]".
std::string named(std::string m, const std::vector<std::string>& names, const std::string& word) {
  const std::string tag = word + " #";
  for (std::size_t at = m.find(tag); at != std::string::npos; at = m.find(tag, at + 1)) {
    std::size_t end = at + tag.size();
    while (end < m.size() && std::isdigit(static_cast<unsigned char>(m[end]))) ++end;
    if (end == at + tag.size()) continue;
    const std::size_t k = std::stoul(m.substr(at + tag.size(), end - at - tag.size()));
    if (k < names.size()) m.replace(at, end - at, word + " \"" + names[k] + "\"");
  }
  return m;
}

void build_figures(const surface::BuildReport& b, StepReport& rep) {
  rep.figures = {{"degree_u", static_cast<long long>(b.degree_u)},
                 {"degree_v", static_cast<long long>(b.degree_v)},
                 {"control_points", static_cast<long long>(b.count_u) * b.count_v},
                 {"rational", b.rational},
                 {"exact", b.exact},
                 {"max_deviation_mm", b.max_deviation_mm}};
  rep.message = b.brief();
}

/// Why a step is light, in the recipe's words: the exact size against the budget.
std::string light_reason(const deform::StepOutcome& o, const Composition& c) {
  const deform::ExactSize& x = o.exact_size;
  return "the exact form would have degree " + std::to_string(x.degree_u) + " x " +
         std::to_string(x.degree_v) +
         (x.control_points > 0
              ? " and up to " + std::to_string(x.control_points) + " control points"
              : std::string()) +
         ", above the budget (degree " + std::to_string(c.budget->max_degree) + ", " +
         std::to_string(c.budget->max_control_points) + " control points)";
}

void style_figures(const deform::StyleResult& r, StepReport& rep) {
  const deform::StyleReport& x = r.report;
  rep.figures = {{"mode", std::string(x.mode == deform::StyleMode::Exact ? "exact" : "paper")},
                 {"constraint_class", std::string(deform::to_string(x.constraint_class))},
                 {"key_points", static_cast<long long>(x.key_points.size())},
                 {"influenced_vertices", static_cast<long long>(x.influenced_vertices)},
                 {"moved_vertices", static_cast<long long>(x.moved_vertices)},
                 {"max_displacement", x.max_displacement},
                 {"target_deviation", x.target_deviation},
                 {"target_curve_deviation", x.target_curve_deviation},
                 {"target_curve_distance", x.target_curve_distance},
                 {"mean_curvature_min", x.mean_curvature_min},
                 {"mean_curvature_max", x.mean_curvature_max},
                 {"curvature_waves", static_cast<long long>(x.curvature_waves)},
                 {"locality", x.locality},
                 {"boundary_position_jump", x.boundary_position_jump},
                 {"boundary_tangent_angle", x.boundary_tangent_angle},
                 {"knots_inserted", static_cast<long long>(x.knots_inserted)},
                 {"added_key_points", static_cast<long long>(x.added_key_points)},
                 {"net_change", x.net_change},
                 {"fairness_energy", x.fairness_energy},
                 {"degree_u", static_cast<long long>(r.surface.u.degree)},
                 {"degree_v", static_cast<long long>(r.surface.v.degree)},
                 {"control_points", static_cast<long long>(r.surface.points.rows())}};
}

}  // namespace clay::recipe::detail
