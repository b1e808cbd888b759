// Example 01 — build two surfaces, export them to STEP (AP214), IGES and a glTF preview, read the
// files back, check that nothing was lost, and write report.json.
//
//   example_01_export_surfaces OUTPUT_DIR
//
// The surfaces: a bicubic "hood" (8 x 6 control points, polynomial) and an exact rational torus
// patch (biquadratic, a quarter of the tube swept a quarter turn). Exits non-zero if a read-back
// differs by a single bit or a face fails OpenCASCADE's BRepCheck.
#include <clay/occt.hpp>
#include <clay/surface.hpp>

#include <nlohmann/json.hpp>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>

using namespace clay::surface;
namespace fs = std::filesystem;

namespace {

/// A gently curved bicubic hood, 800 x 500 mm, crowned 60 mm.
BSplineSurface hood() {
  const int nu = 8, nv = 6;
  BSplineBasis u{3, {0, 0, 0, 0, 0.2, 0.4, 0.6, 0.8, 1, 1, 1, 1}};
  BSplineBasis v = clamped_uniform_basis(3, nv);
  Points3 p(nu * nv, 3);
  for (int i = 0; i < nu; ++i)
    for (int j = 0; j < nv; ++j) {
      const double x = 800.0 * i / (nu - 1), y = 500.0 * j / (nv - 1) - 250.0;
      const double z = 60.0 * std::sin(M_PI * i / (nu - 1)) * std::cos(0.5 * M_PI * y / 250.0);
      p.row(i * nv + j) << x, y, z;
    }
  return make_surface(std::move(u), std::move(v), std::move(p));
}

/// Torus patch (major radius R, minor r): the rational quarter circle of the tube revolved by a
/// rational quarter circle about z. Every point lies on the torus exactly.
BSplineSurface torus_patch(double R, double r) {
  const double w = std::sqrt(0.5);
  const double ring[3][2] = {{1, 0}, {1, 1}, {0, 1}};          // about z, weights 1, w, 1
  const double tube[3][2] = {{R + r, 0}, {R + r, r}, {R, r}};  // (radius, z), weights 1, w, 1
  const double wt[3] = {1, w, 1};
  Points3 p(9, 3);
  Eigen::VectorXd weights(9);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      p.row(i * 3 + j) << tube[j][0] * ring[i][0], tube[j][0] * ring[i][1], tube[j][1];
      weights[i * 3 + j] = wt[i] * wt[j];
    }
  const BSplineBasis arc{2, {0, 0, 0, 1, 1, 1}};
  return make_surface(arc, arc, std::move(p), std::move(weights));
}

double torus_error(const BSplineSurface& s, double R, double r) {
  double worst = 0;
  for (double u : linspace(0, 1, 41))
    for (double v : linspace(0, 1, 41)) {
      const Eigen::Vector3d x = evaluate(s, u, v);
      worst = std::max(worst, std::abs(std::hypot(std::hypot(x.x(), x.y()) - R, x.z()) - r));
    }
  return worst;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: %s OUTPUT_DIR\n", argv[0]);
    return 2;
  }
  try {
    const fs::path out = argv[1];
    fs::create_directories(out);
    const std::vector<BSplineSurface> surfaces = {hood(), torus_patch(300.0, 80.0)};

    using clock = std::chrono::steady_clock;
    const auto t0 = clock::now();
    const ExchangeReport step = write_step(surfaces, out / "sample.step");
    const ExchangeReport iges = write_iges(surfaces, out / "sample.igs");
    write_gltf(surfaces, out / "sample.glb");
    const auto t1 = clock::now();
    const auto from_step = read_step(out / "sample.step");
    const auto from_iges = read_iges(out / "sample.igs");
    const auto t2 = clock::now();

    bool lossless = from_step.size() == surfaces.size() && from_iges.size() == surfaces.size();
    for (size_t k = 0; lossless && k < surfaces.size(); ++k)
      lossless = identical(from_step[k], surfaces[k]) && identical(from_iges[k], surfaces[k]);
    const double torus_dev = torus_error(from_step[1], 300.0, 80.0);

    nlohmann::json report;
    report["example"] = "01_export_surfaces";
    report["surfaces"] = nlohmann::json::array();
    for (const auto& s : surfaces)
      report["surfaces"].push_back({{"degree", {s.u.degree, s.v.degree}},
                                    {"control_points", s.points.rows()},
                                    {"rational", s.is_rational()}});
    report["step"] = {{"file", "sample.step"},
                      {"schema", "AP214"},
                      {"faces", step.faces},
                      {"valid", step.valid},
                      {"bytes", fs::file_size(out / "sample.step")}};
    report["iges"] = {{"file", "sample.igs"},
                      {"faces", iges.faces},
                      {"valid", iges.valid},
                      {"bytes", fs::file_size(out / "sample.igs")}};
    report["gltf"] = {{"file", "sample.glb"}, {"bytes", fs::file_size(out / "sample.glb")}};
    report["round_trip_bit_identical"] = lossless;
    report["torus_radius_error_mm"] = torus_dev;
    report["timings_ms"] = {{"write", std::chrono::duration<double, std::milli>(t1 - t0).count()},
                            {"read", std::chrono::duration<double, std::milli>(t2 - t1).count()}};
    std::ofstream(out / "report.json") << report.dump(2) << "\n";

    std::printf("wrote %s (AP214, %d faces, %s), %s, %s\n", (out / "sample.step").c_str(),
                step.faces, step.valid ? "BRepCheck valid" : "INVALID",
                (out / "sample.igs").c_str(), (out / "sample.glb").c_str());
    std::printf("read back: %s; torus radius error %.2e mm; report %s\n",
                lossless ? "bit-identical" : "DIFFERENT", torus_dev, (out / "report.json").c_str());
    return (lossless && step.valid && iges.valid && torus_dev < 1e-9) ? 0 : 1;
  } catch (const clay::Error& e) {
    std::fprintf(stderr, "example 01: %s\n", e.what());
    return 1;
  }
}
