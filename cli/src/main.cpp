// clayform — the command-line shell over the kernel: parse, call one library function, print the
// outcome, map error categories to exit codes (STYLE.md rule 18).
#include <clay/deform.hpp>

#include <CLI/CLI.hpp>

#include <cctype>
#include <charconv>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <string>

namespace {

namespace fs = std::filesystem;
using namespace clay::surface;

/// Exit codes: 0 success, 1 usage (CLI11), then one per error category.
int exit_code(clay::ErrorCategory c) {
  switch (c) {
    case clay::ErrorCategory::InvalidArgument: return 2;
    case clay::ErrorCategory::InvalidGeometry: return 3;
    case clay::ErrorCategory::OutOfDomain: return 3;
    case clay::ErrorCategory::DegreeLimit: return 4;
    case clay::ErrorCategory::Io: return 5;
    case clay::ErrorCategory::Exchange: return 6;
    case clay::ErrorCategory::Recipe: return 7;
    case clay::ErrorCategory::Internal: return 70;
  }
  return 70;
}

/// Distinct knots with multiplicities, "0^4 0.2 0.4 1^4", each value in its shortest exact form.
std::string knots_summary(const BSplineBasis& b) {
  std::string out;
  char buf[64];
  for (double k : breakpoints(b)) {
    const auto end = std::to_chars(buf, buf + sizeof buf, k).ptr;
    if (!out.empty()) out += ' ';
    out.append(buf, end);
    const int m = multiplicity(b, k);
    if (m > 1) out += "^" + std::to_string(m);
  }
  return out;
}

/// `clayform info FILE`: lists the surfaces of a STEP or IGES file.
int info(const fs::path& file) {
  std::string ext = file.extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  std::vector<BSplineSurface> surfaces;
  if (ext == ".step" || ext == ".stp")
    surfaces = read_step(file);
  else if (ext == ".igs" || ext == ".iges")
    surfaces = read_iges(file);
  else
    throw clay::Error(clay::ErrorCategory::InvalidArgument,
                      "info: '" + file.string() + "' has extension '" + ext +
                          "'; give a .step/.stp or .igs/.iges file");
  const ExchangeReport check = check_faces(surfaces);
  std::printf("%s: %zu surface(s), BRepCheck %s at %.0e mm\n", file.string().c_str(), surfaces.size(),
              check.valid ? "valid" : "INVALID", check.tolerance);
  for (size_t k = 0; k < surfaces.size(); ++k) {
    const BSplineSurface& s = surfaces[k];
    const auto [lo, hi] = control_box(s);
    std::printf("  #%zu degree (%d, %d), %d x %d control points, %s\n", k, s.u.degree, s.v.degree,
                s.count_u(), s.count_v(), s.is_rational() ? "rational" : "polynomial");
    std::printf("     u knots %s\n     v knots %s\n", knots_summary(s.u).c_str(), knots_summary(s.v).c_str());
    std::printf("     control box [%.6g, %.6g, %.6g] .. [%.6g, %.6g, %.6g] mm\n", lo.x(), lo.y(), lo.z(),
                hi.x(), hi.y(), hi.z());
  }
  for (const auto& p : check.problems) std::printf("  problem: %s\n", p.c_str());
  return check.valid ? 0 : exit_code(clay::ErrorCategory::Exchange);
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"clayform — NURBS surface styling kernel"};
  app.set_version_flag("--version", std::string("clayform ") + CLAYFORM_VERSION);
  app.require_subcommand(1);
  std::string file;
  auto* info_cmd = app.add_subcommand("info", "List the surfaces of a STEP or IGES file: degrees, "
                                              "control points, knots, rational, box, validity");
  info_cmd->add_option("FILE", file, "a .step/.stp or .igs/.iges file")->required();
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  }
  try {
    if (*info_cmd) return info(file);
  } catch (const clay::Error& e) {
    std::fprintf(stderr, "clayform: %s\n", e.what());
    return exit_code(e.category());
  }
  return 0;
}
