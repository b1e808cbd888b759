// ModelReadOptions' checks and ModelReadReport's one line (clay/occt/model_exchange.hpp).
#include <clay/internal/checks.hpp>
#include <clay/internal/format.hpp>
#include <clay/occt/model_exchange.hpp>

#include <cstdio>
#include <string>
#include <vector>

namespace clay::brep {

using internal::shortest;

namespace {

/// "brep.colour is (1.2, 0, 0): each component must be a finite number in [0, 1]", if so.
void colour_problem(const std::optional<Colour>& c, const std::string& field,
                    std::vector<std::string>& out) {
  if (!c) return;
  for (double x : {c->r, c->g, c->b})
    if (!(x >= 0 && x <= 1)) {
      out.push_back(field + " is (" + shortest(c->r) + ", " + shortest(c->g) + ", " +
                    shortest(c->b) + "); each component must be a number in [0, 1]");
      return;
    }
}

}  // namespace

std::vector<std::string> BrepAttributes::problems() const {
  std::vector<std::string> out;
  colour_problem(colour, "colour", out);
  for (std::size_t k = 0; k < face_colours.size(); ++k)
    colour_problem(face_colours[k], "face_colours[" + std::to_string(k) + "]", out);
  return out;
}

std::vector<std::string> ModelReadOptions::problems() const {
  std::vector<std::string> out = read.problems();
  for (const std::string& p : brep.problems()) out.push_back("brep." + p);
  if (!(sewing_tolerance_mm > 0 && sewing_tolerance_mm <= 1))
    out.push_back("sewing_tolerance_mm is " + shortest(sewing_tolerance_mm) +
                  "; it must be in (0, 1] mm");
  return out;
}

void ModelReadOptions::validate() const {
  internal::throw_if(ErrorCategory::InvalidArgument, problems());
}

std::string ModelReadReport::brief() const {
  char text[512];
  std::snprintf(text, sizeof text,
                "%d bod%s (%d solid%s), %d shell%s, %d face%s (%d trimmed, %d holes), %d edges, "
                "%d vertices; faces %d B-spline, %d affine, %d angular; pcurves %d kept, %d "
                "exact, %d fitted (<= %.1e mm); edge gap %.1e mm",
                counts.bodies, counts.bodies == 1 ? "y" : "ies", counts.solids,
                counts.solids == 1 ? "" : "s", counts.shells, counts.shells == 1 ? "" : "s",
                counts.faces, counts.faces == 1 ? "" : "s", counts.trimmed_faces,
                counts.inner_loops, counts.edges, counts.vertices, faces_bspline, faces_affine,
                faces_angular, pcurves_kept, pcurves_exact, pcurves_fitted,
                max_rederivation_error_mm, max_edge_gap_mm);
  std::string line = text;
  if (faces_approximated > 0) {
    std::snprintf(text, sizeof text, "; %d offset face%s approximated (<= %.1e mm)",
                  faces_approximated, faces_approximated == 1 ? "" : "s",
                  max_approximation_error_mm);
    line += text;
  }
  if (counts.wires > 0)
    line += "; " + std::to_string(counts.wires) + " wire bod" + (counts.wires == 1 ? "y" : "ies") +
            " (" + std::to_string(counts.wire_edges) + " free edge" +
            (counts.wire_edges == 1 ? "" : "s") + ")";
  if (!left_out.empty())
    line += "; left out " + std::to_string(left_out.size()) + ": " + left_out.front();
  if (!healing.empty()) line += "; healed: " + healing.front();
  if (!ignored.empty())
    line += "; ignored " + std::to_string(ignored.size()) + " unknown entity type" +
            (ignored.size() == 1 ? "" : "s") + ": " + ignored.front();
  if (!skipped.empty())
    line += "; skipped " + std::to_string(skipped.size()) + " entit" +
            (skipped.size() == 1 ? "y" : "ies") +
            " OpenCASCADE could not transfer: " + skipped.front();
  if (!problems.empty())
    line += "; " + std::to_string(problems.size()) + " problems, the first: " + problems.front();
  return line;
}

}  // namespace clay::brep
