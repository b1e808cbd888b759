// Receiver profiles: conformance and the certified fit to a profile (receiver.hpp).
#include <clay/deform/receiver.hpp>

#include <clay/error.hpp>
#include <clay/surface/degree_elevation.hpp>

#include <algorithm>
#include <string>

#include "messages.hpp"

namespace clay::deform {

const std::vector<ReceiverProfile>& receiver_profiles() {
  static const std::vector<ReceiverProfile> all = {
      {"exact", 25, 1, 0, 0},   {"opencascade", 25, 1, 0, 3}, {"catia", 15, 1, 0, 3},
      {"class_a", 5, 1, 32, 5}, {"bicubic", 3, 3, 0, 3},
  };
  return all;
}

const ReceiverProfile& receiver_profile(std::string_view name) {
  std::string names;
  for (const ReceiverProfile& p : receiver_profiles()) {
    if (p.name == name) return p;
    names += (names.empty() ? "" : ", ") + std::string(p.name);
  }
  throw Error(ErrorCategory::InvalidArgument,
              "no receiver profile \"" + std::string(name) + "\"; the profiles: " + names);
}

std::vector<std::string> conformance_problems(const surface::BSplineSurface& s,
                                              const ReceiverProfile& p) {
  std::vector<std::string> out;
  const std::string profile = "the " + std::string(p.name) + " profile";
  for (const auto& [dir, basis] : {std::pair{"u", &s.u}, std::pair{"v", &s.v}}) {
    if (basis->degree > p.max_degree)
      out.push_back(std::string("degree ") + std::to_string(basis->degree) + " in " + dir +
                    " is above " + profile + "'s " + std::to_string(p.max_degree));
    if (basis->degree < p.min_degree)
      out.push_back(std::string("degree ") + std::to_string(basis->degree) + " in " + dir +
                    " is below " + profile + "'s " + std::to_string(p.min_degree));
    if (p.max_count_per_direction > 0 && basis->count() > p.max_count_per_direction)
      out.push_back(std::to_string(basis->count()) + " control points in " + dir +
                    " are more than " + profile + "'s " +
                    std::to_string(p.max_count_per_direction));
  }
  return out;
}

ProfileFit fit_to_profile(const surface::BSplineSurface& s, const ReceiverProfile& p,
                          RefitOptions fit, std::string_view name) {
  surface::validate(s, std::string(name));
  ProfileFit out{s, false, false, 0, {}};
  std::vector<std::string> problems = conformance_problems(s, p);
  if (problems.empty()) return out;
  // Only too low a degree (the bicubic profile, which caps no net): raised exactly.
  const bool only_low =
      std::max(s.u.degree, s.v.degree) <= p.max_degree && p.max_count_per_direction == 0;
  if (only_low) {
    if (s.u.degree < p.min_degree)
      out.surface = surface::elevate_degree_u(out.surface, p.min_degree - s.u.degree);
    if (s.v.degree < p.min_degree)
      out.surface = surface::elevate_degree_v(out.surface, p.min_degree - s.v.degree);
    out.elevated = true;
    return out;
  }
  if (p.fit_degree == 0)
    throw Error(ErrorCategory::DegreeLimit,
                std::string(name) + " cannot be written exactly: " + problems.front() +
                    " (the STEP/IGES writers' limit); choose a profile that refits it (e.g. "
                    "\"opencascade\") or lower the degree of the steps that build it");
  fit.degree = p.fit_degree;
  fit.keep_breakpoints = false;
  RefitResult r;
  if (p.max_count_per_direction > 0) {
    // A capped net (class A): adaptive from a uniform 8 x 8 start (from the original's breaks a
    // degree 5 fit would keep every C2 join of a bicubic, rougher than its own C4 joins), the
    // spans with the worst cells split first up to the cap.
    fit.initial_count = std::min(p.fit_degree + 3, p.max_count_per_direction);
    fit.max_count_per_direction = p.max_count_per_direction;
  }
  r = refit_surface(s, fit);
  std::vector<std::string> still = conformance_problems(r.surface, p);
  if (!r.report.summary.converged() || !r.report.certified || !still.empty())
    throw Error(ErrorCategory::ToleranceNotMet,
                std::string(name) + " does not conform to the " + std::string(p.name) +
                    " profile (" + problems.front() + "), and its refit at degree " +
                    std::to_string(p.fit_degree) +
                    (still.empty() ? " misses the tolerance: " + r.report.summary.message
                                   : " does not conform either: " + still.front()) +
                    "; loosen the tolerance, or choose a profile with a larger net");
  out.surface = std::move(r.surface);
  out.refitted = true;
  out.bound_mm = r.report.certified_bound_mm;
  out.report = std::move(r.report);
  return out;
}

}  // namespace clay::deform
