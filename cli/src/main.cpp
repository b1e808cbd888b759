// clayform — the command-line shell over the kernel: parse, call one library function, print the
// outcome, map error categories to exit codes (STYLE.md rule 18).
#include <clay/brep/continuity.hpp>
#include <clay/deform.hpp>
#include <clay/occt/model_exchange.hpp>
#include <clay/recipe/recipe.hpp>
#include <clay/render/render.hpp>
#include <clay/serve.hpp>
#include <clay/studio.hpp>
#include <clay/surface/tessellate.hpp>

#include <CLI/CLI.hpp>

#include <pthread.h>
#include <signal.h>
#include <unistd.h>
#include <algorithm>
#include <cctype>
#include <cerrno>
#include <charconv>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>
#include <string>
#include <variant>

namespace {

namespace fs = std::filesystem;
using namespace clay::surface;

/// Exit codes: 0 success, 1 usage (CLI11), then one per error category.
int exit_code(clay::ErrorCategory c) {
  switch (c) {
    case clay::ErrorCategory::InvalidArgument:
      return 2;
    case clay::ErrorCategory::InvalidGeometry:
      return 3;
    case clay::ErrorCategory::OutOfDomain:
      return 3;
    case clay::ErrorCategory::DegreeLimit:
      return 4;
    case clay::ErrorCategory::Io:
      return 5;
    case clay::ErrorCategory::Exchange:
      return 6;
    case clay::ErrorCategory::Document:
      return 7;
    case clay::ErrorCategory::ToleranceNotMet:
      return 8;
    case clay::ErrorCategory::Internal:
      return 70;
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

/// The whole model of a STEP or IGES file (brep::read_model), read in a child process
/// (ReadOptions::isolate): a file that crashes or hangs OpenCASCADE ends in exit code 6 and a
/// message, never in a signal.
clay::brep::ImportedModel read_model_file(const fs::path& file, const char* command,
                                          bool strict = false) {
  std::string ext = file.extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  if (ext != ".step" && ext != ".stp" && ext != ".igs" && ext != ".iges")
    throw clay::Error(clay::ErrorCategory::InvalidArgument,
                      std::string(command) + ": '" + file.string() + "' has extension '" + ext +
                          "'; give a .step/.stp or .igs/.iges file");
  clay::brep::ModelReadOptions options;
  options.read.isolate = true;
  options.strict = strict;
  return clay::brep::read_model(file, options);
}

std::string quoted_name(const std::string& name) { return name.empty() ? "" : " \"" + name + "\""; }

std::string colour_text(const std::optional<clay::brep::Colour>& c) {
  if (!c) return "";
  char buf[64];
  std::snprintf(buf, sizeof buf, " colour (%.3g, %.3g, %.3g)", c->r, c->g, c->b);
  return buf;
}

/// The assembly tree, indented: each instance's name, its part's name and where it is placed.
void print_tree(const clay::brep::Model& m, const clay::brep::Instance& in, int depth) {
  if (depth > static_cast<int>(m.parts.size())) return;  // cycles are problems, printed apart
  const auto& part = m.parts[static_cast<size_t>(in.part)];
  const Eigen::Vector3d t = in.placement.translation();
  const bool turned = !in.placement.linear().isIdentity(1e-12);
  std::printf("  %*s%s%s at (%.6g, %.6g, %.6g)%s%s: %zu bod%s\n", 2 * depth, "",
              part.name.empty() ? "(unnamed part)" : ("\"" + part.name + "\"").c_str(),
              in.name.empty() || in.name == part.name ? "" : (" as \"" + in.name + "\"").c_str(),
              t.x(), t.y(), t.z(), turned ? ", turned" : "", colour_text(part.colour).c_str(),
              part.bodies.size(), part.bodies.size() == 1 ? "y" : "ies");
  for (const auto& c : part.components) print_tree(m, c, depth + 1);
}

/// How the faces meet along their edges (brep::edge_continuity): the summary, then the smooth
/// joins (tangent planes within 10 degrees: fillets, blends, seams), worst angle first, at most 20:
/// where a class-A check looks. Sharp edges are in the summary only.
void print_continuity(const clay::brep::Model& m) {
  const clay::brep::ContinuityReport r = clay::brep::edge_continuity(m);
  std::printf("  continuity: %s\n", r.brief().c_str());
  std::vector<clay::brep::EdgeContinuity> smooth;
  for (const auto& e : r.edges)
    if (e.angle_deg < 10) smooth.push_back(e);
  std::sort(smooth.begin(), smooth.end(),
            [](const auto& a, const auto& b) { return a.angle_deg > b.angle_deg; });
  if (!smooth.empty()) std::printf("  smooth joins (angle < 10 deg), worst first:\n");
  for (std::size_t k = 0; k < smooth.size() && k < 20; ++k) {
    const auto& e = smooth[k];
    std::printf(
        "    edge %d (faces %d, %d): gap %.2g mm, angle %.2g deg, curvature jump %.3g /mm "
        "(relative %.3g)\n",
        e.edge, e.face_a, e.face_b, e.gap_mm, e.angle_deg, e.curvature_jump,
        e.relative_curvature_jump);
  }
  if (smooth.size() > 20) std::printf("    ... and %zu more\n", smooth.size() - 20);
}

/// `clayform info FILE`: the topology of a STEP or IGES file (bodies, shells, trimmed faces and
/// holes, the assembly tree with names), OpenCASCADE's verdict, each face's surface, and how the
/// faces meet along their edges.
int info(const fs::path& file, bool strict) {
  const clay::brep::ImportedModel read = read_model_file(file, "info", strict);
  const clay::brep::Model& m = read.model;
  int max_degree = 0;
  long control_points = 0;
  for (const auto& f : m.faces) {
    max_degree = std::max({max_degree, f.surface.u.degree, f.surface.v.degree});
    control_points += static_cast<long>(f.surface.points.rows());
  }
  const bool broken = !read.report.problems.empty();
  clay::brep::ModelCheck check;
  if (!broken) check = clay::brep::check_model(m);
  // An edge gap beyond 1 % of the model's size is no rounding, whatever tolerance the file gave
  // its edges: never "valid" over it (a file with a duplicated entity read as valid with a 25 mm
  // gap on a 2 mm part, issue #36).
  Eigen::Vector3d low = Eigen::Vector3d::Constant(1e300), high = -low;
  for (const auto& f : m.faces) {
    const auto [a, b] = control_box(f.surface);
    low = low.cwiseMin(a);
    high = high.cwiseMax(b);
  }
  const double size = m.faces.empty() ? 0.0 : (high - low).norm();
  if (check.valid && read.report.max_edge_gap_mm > 0.01 * size) {
    check.valid = false;
    check.problems.insert(check.problems.begin(),
                          "an edge gap of " + std::to_string(read.report.max_edge_gap_mm) +
                              " mm is more than 1 % of the model's size (" + std::to_string(size) +
                              " mm): its edges do not meet its faces");
  }
  std::printf("%s: %zu face%s, max degree %d, %ld control points, %s\n", file.string().c_str(),
              m.faces.size(), m.faces.size() == 1 ? "" : "s", max_degree, control_points,
              broken ? "NOT valid (broken invariants)" : check.brief().c_str());
  std::printf("  read: %s\n", read.report.brief().c_str());
  for (const auto& h : read.report.healing) std::printf("  healed: %s\n", h.c_str());
  for (const auto& h : read.report.ignored) std::printf("  ignored: %s\n", h.c_str());
  for (const auto& h : read.report.skipped) std::printf("  skipped: %s\n", h.c_str());
  for (const auto& h : read.report.left_out) std::printf("  left out: %s\n", h.c_str());
  for (size_t b = 0; b < m.bodies.size(); ++b) {
    const auto& body = m.bodies[b];
    if (body.kind == clay::brep::BodyKind::Wire) {
      std::printf("  body %zu: wire%s%s, %zu free edge%s\n", b, quoted_name(body.name).c_str(),
                  colour_text(body.colour).c_str(), body.edges.size(),
                  body.edges.size() == 1 ? "" : "s");
      continue;
    }
    int faces = 0, trimmed = 0, holes = 0;
    for (const auto& shell : body.shells)
      for (int f : shell.faces) {
        const auto& face = m.faces[static_cast<size_t>(f)];
        ++faces;
        trimmed += !face.loops.empty();
        holes += face.loops.empty() ? 0 : static_cast<int>(face.loops.size()) - 1;
      }
    std::printf("  body %zu: %s%s%s, %zu shell%s, %d face%s (%d trimmed, %d hole%s)\n", b,
                std::string(clay::brep::to_string(body.kind)).c_str(),
                quoted_name(body.name).c_str(), colour_text(body.colour).c_str(),
                body.shells.size(), body.shells.size() == 1 ? "" : "s", faces,
                faces == 1 ? "" : "s", trimmed, holes, holes == 1 ? "" : "s");
  }
  if (m.is_assembly()) {
    std::printf("  assembly:\n");
    for (const auto& root : m.roots) print_tree(m, root, 0);
  }
  for (size_t k = 0; k < m.faces.size(); ++k) {
    const auto& face = m.faces[k];
    const BSplineSurface& s = face.surface;
    const auto [lo, hi] = control_box(s);
    std::printf(
        "  #%zu %sdegree (%d, %d), %d x %d control points, %s%s%s, %s\n", k,
        face.elementary ? (std::string(to_string(face.elementary->kind)) + ", ").c_str() : "",
        s.u.degree, s.v.degree, s.count_u(), s.count_v(),
        s.is_rational() ? "rational" : "polynomial", quoted_name(face.name).c_str(),
        colour_text(face.colour).c_str(),
        face.loops.empty()       ? "untrimmed"
        : face.loops.size() == 1 ? "trimmed"
                                 : ("trimmed, " + std::to_string(face.loops.size() - 1) + " hole" +
                                    (face.loops.size() == 2 ? "" : "s"))
                                       .c_str());
    std::printf("     u knots %s\n     v knots %s\n", knots_summary(s.u).c_str(),
                knots_summary(s.v).c_str());
    std::printf("     control box [%.6g, %.6g, %.6g] .. [%.6g, %.6g, %.6g] mm\n", lo.x(), lo.y(),
                lo.z(), hi.x(), hi.y(), hi.z());
  }
  if (!broken) print_continuity(m);
  for (const auto& p : read.report.problems) std::printf("  problem: %s\n", p.c_str());
  for (const auto& p : check.problems) std::printf("  problem: %s\n", p.c_str());
  if (broken) return exit_code(clay::ErrorCategory::InvalidGeometry);
  return check.valid ? 0 : exit_code(clay::ErrorCategory::Exchange);
}

/// A figure for a progress line: numbers in short form.
std::string figure_text(const clay::recipe::Figure& f) {
  return std::visit(
      [](const auto& x) -> std::string {
        using T = std::decay_t<decltype(x)>;
        if constexpr (std::is_same_v<T, bool>)
          return x ? "yes" : "no";
        else if constexpr (std::is_same_v<T, std::string>)
          return x;
        else if constexpr (std::is_same_v<T, double>) {
          char buf[32];
          std::snprintf(buf, sizeof buf, "%.3g", x);
          return buf;
        } else
          return std::to_string(x);
      },
      f);
}

/// Progress: one line per step, "[3] surfaces.sail (fill) 0.012 s: degree_u 3, ...".
clay::recipe::RunOptions run_options(bool show) {
  clay::recipe::RunOptions o;
  if (!show) return o;
  o.progress = [count = 0](const clay::recipe::StepReport& r) mutable {
    std::string figures;
    int shown = 0;
    for (const auto& [name, value] : r.figures) {
      if (shown++ == 6) break;
      figures += (figures.empty() ? "" : ", ") + name + " " + figure_text(value);
    }
    std::printf("[%d] %s (%s) %.3f s%s%s%s\n", ++count, r.path.c_str(), r.kind.c_str(), r.seconds,
                figures.empty() ? "" : ": ", figures.c_str(), r.warning ? "  WARNING" : "");
    if (r.warning) std::printf("    %s\n", r.message.c_str());
    std::fflush(stdout);
  };
  return o;
}

/// Writes the outputs and lists them. An export that reads back invalid throws in write_outputs
/// before anything is written, so every export listed here is valid.
int finish(clay::recipe::RunResult& result, const fs::path& out) {
  const auto files = clay::recipe::write_outputs(result, out);
  std::printf("%s: %zu step(s) in %.2f s\n", result.recipe.c_str(), result.steps.size(),
              result.seconds);
  // How each deformed surface was computed: exact composition or certified refit, and how close.
  for (const auto& step : result.steps) {
    const clay::recipe::Figure* mode = nullptr;
    double relative = -1, mm = -1, accumulated = -1;
    long long exact_points = 0;
    for (const auto& [name, value] : step.figures) {
      if (name == "composition") mode = &value;
      if (name == "max_relative_deviation" && std::holds_alternative<double>(value))
        relative = std::get<double>(value);
      if (name == "max_deviation_mm" && std::holds_alternative<double>(value))
        mm = std::get<double>(value);
      if (name == "accumulated_bound_mm" && std::holds_alternative<double>(value))
        accumulated = std::get<double>(value);
      if (name == "exact_control_points" && std::holds_alternative<long long>(value))
        exact_points = std::get<long long>(value);
    }
    if (mode && relative >= 0) {
      std::printf("  %s (%s): %s composition, max deviation %.2g of the size (%.2g mm)",
                  step.path.c_str(), step.kind.c_str(), std::get<std::string>(*mode).c_str(),
                  relative, mm);
      if (exact_points > 0) std::printf(" instead of %lld exact control points", exact_points);
      if (accumulated >= 0) std::printf(", within %.2g mm of the exact result", accumulated);
      std::printf("\n");
    }
    if (step.kind == "light") std::printf("  %s: %s\n", step.path.c_str(), step.message.c_str());
  }
  // Warnings reach the user whether or not progress is shown (a script's run has no terminal).
  for (const auto& step : result.steps)
    if (step.warning)
      std::fprintf(stderr, "clayform: warning: %s (%s): %s\n", step.path.c_str(), step.kind.c_str(),
                   step.message.c_str());
  for (const auto& e : result.exports)
    if (e.checked)
      std::printf("  export %s: %zu surface(s), read back valid (BRepCheck)%s\n", e.name.c_str(),
                  e.surfaces.size(), e.read_back_identical ? ", bit-identical" : "");
  std::printf("outputs in %s:\n", out.string().c_str());
  for (const auto& f : files) std::printf("  %s\n", f.string().c_str());
  return 0;
}

/// `clayform deform FILE --recipe R --out DIR`: the whole model of a STEP or IGES file (trimmed
/// faces, solids, assembly) through the recipe's deformation stack, written as a valid model.
int deform_model_file(const fs::path& file, const fs::path& recipe_file,
                      const std::string& deformation, const fs::path& out, bool show,
                      bool allow_fold, const std::string& profile, bool strict) {
  const auto recipe = clay::recipe::load_recipe(recipe_file);
  if (!profile.empty()) clay::deform::receiver_profile(profile);  // a typo fails at once
  const auto start = std::chrono::steady_clock::now();
  const clay::brep::ImportedModel read = read_model_file(file, "deform", strict);
  if (show) std::printf("read %s: %s\n", file.string().c_str(), read.report.brief().c_str());
  if (!read.report.problems.empty()) {
    std::string m = "deform: the model of '" + file.string() + "' breaks " +
                    std::to_string(read.report.problems.size()) +
                    " invariant(s), so it is not deformed:";
    for (const auto& p : read.report.problems) m += "\n  " + p;
    throw clay::Error(clay::ErrorCategory::InvalidGeometry, m);
  }
  const auto result =
      clay::recipe::deform_model(recipe, read.model, deformation, allow_fold, profile);
  if (show)
    std::printf("deformed by %s: %s\n", result.deformation.c_str(), result.report.brief().c_str());
  const auto files = clay::recipe::write_model_outputs(result, out, file.stem().string());
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::printf("%s: %s in %.2f s\n", file.string().c_str(), result.report.brief().c_str(), seconds);
  for (const auto& k : result.kept) {
    auto has = [&](const char* p) {
      return std::find(k.properties.begin(), k.properties.end(), p) != k.properties.end();
    };
    if (has("volume") || has("centroid"))
      std::printf("  %s kept the volume %.10g -> %.10g mm^3 (centroid moved %.2g mm)\n",
                  k.step.c_str(), k.volume_before_mm3, k.volume_after_mm3, k.centroid_shift_mm);
    if (has("area"))
      std::printf("  %s kept the area %.10g -> %.10g mm^2\n", k.step.c_str(), k.area_before_mm2,
                  k.area_after_mm2);
    std::printf("  %s: %d Newton steps, points corrected by up to %.3g mm\n", k.step.c_str(),
                k.iterations, k.largest_correction_mm);
  }
  if (!result.fold_free)
    std::printf(
        "  WARNING: a lattice may fold (a Jacobian bound <= 0, allowed by --allow-fold): "
        "the solid may intersect itself\n");
  std::printf("outputs in %s (read back valid, BRepCheck):\n", out.string().c_str());
  for (const auto& f : files) std::printf("  %s\n", f.string().c_str());
  return 0;
}

/// `clayform validate RECIPE`: every problem, with its location.
int validate(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in)
    throw clay::Error(clay::ErrorCategory::Io,
                      "validate: cannot read '" + file.string() + "'; check the path");
  std::ostringstream text;
  text << in.rdbuf();
  const auto problems = clay::recipe::check_recipe(text.str(), file.parent_path());
  if (problems.empty()) {
    const auto recipe = clay::recipe::parse_recipe(text.str(), file.parent_path());
    std::printf("%s: valid recipe\n", file.string().c_str());
    return 0;
  }
  std::printf("%s: %zu problem%s\n", file.string().c_str(), problems.size(),
              problems.size() == 1 ? "" : "s");
  for (const auto& p : problems) std::printf("  %s\n", clay::recipe::to_string(p).c_str());
  return exit_code(clay::ErrorCategory::Document);
}

// ---- clayform render (clay/render/render.hpp) ----

/// `clayform render FILE --png OUT.png`: a picture of the model of a STEP or IGES file, its faces
/// trimmed (holes are holes), coloured as the file colours them.
int render_picture(const fs::path& file, const fs::path& png, clay::render::RenderOptions options,
                   bool eye_given, const clay::brep::MeshOptions& mesh_options) {
  const clay::brep::ImportedModel read = read_model_file(file, "render");
  const auto start = std::chrono::steady_clock::now();
  const clay::brep::ModelMesh mesh = clay::brep::tessellate(read.model, mesh_options);
  // Without --eye, an open panel is pictured from its front, not from behind.
  if (!eye_given) options.eye_direction = clay::render::facing_eye(mesh, options.eye_direction);
  std::vector<BSplineSurface> nets;
  if (options.control_net)
    for (const auto& face : clay::brep::flattened(read.model).faces) nets.push_back(face.surface);
  const clay::render::Image image = clay::render::render_mesh(mesh, options, nets);
  const double ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  clay::render::write_png(image, png);
  std::printf("%s: %zu face(s), %zu triangles -> %s (%d x %d, %.0f ms)\n", file.string().c_str(),
              read.model.faces.size(), mesh.triangles.size(), png.string().c_str(), image.width,
              image.height, ms);
  return 0;
}

/// The surfaces of a run as one model mesh (a face per surface, body -1), for render_mesh and
/// facing_eye.
clay::brep::ModelMesh mesh_of(const std::vector<BSplineSurface>& surfaces) {
  clay::brep::ModelMesh mesh;
  for (std::size_t k = 0; k < surfaces.size(); ++k) {
    const clay::surface::GridMesh g = clay::surface::tessellate(surfaces[k], 8, 401);
    const int first = static_cast<int>(mesh.positions.size());
    for (Eigen::Index r = 0; r < g.positions.rows(); ++r) {
      mesh.positions.push_back(g.positions.row(r).transpose());
      mesh.normals.push_back(g.normals.row(r).transpose());
      mesh.uv.emplace_back(g.us[static_cast<std::size_t>(r / g.cols)],
                           g.vs[static_cast<std::size_t>(r % g.cols)]);
      mesh.node_face.push_back(static_cast<int>(k));
    }
    for (int i = 0; i + 1 < g.rows; ++i)
      for (int j = 0; j + 1 < g.cols; ++j)
        for (auto t : clay::surface::cell_triangles(g, i, j)) {
          for (int& c : t) c += first;
          mesh.triangles.push_back(t);
          mesh.triangle_face.push_back(static_cast<int>(k));
        }
    mesh.face_body.push_back(static_cast<int>(k));  // a colour per surface
    mesh.face_colours.emplace_back();
  }
  return mesh;
}

/// `clayform render RECIPE.json --png OUT.png`: runs the recipe (nothing written) and pictures
/// its final surfaces (those no deform step takes as parent) with its named curves over them.
int render_recipe(const fs::path& file, const fs::path& png, clay::render::RenderOptions options,
                  bool eye_given, bool curves) {
  const auto recipe = clay::recipe::load_recipe(file);
  const auto result = clay::recipe::run_recipe(recipe, {});
  const auto start = std::chrono::steady_clock::now();
  const std::vector<std::string> names = clay::recipe::final_surfaces(recipe);
  std::vector<BSplineSurface> surfaces;
  for (const auto& n : names) surfaces.push_back(result.surface(n));
  if (surfaces.empty())
    throw clay::Error(
        clay::ErrorCategory::InvalidArgument,
        "render: the recipe " + file.string() + " builds no surface; add one under \"surfaces\"");
  std::vector<clay::surface::BSplineCurve> drawn;
  if (curves)
    for (const auto& [n, c] : result.curves) drawn.push_back(c);
  const clay::brep::ModelMesh mesh = mesh_of(surfaces);
  if (!eye_given) options.eye_direction = clay::render::facing_eye(mesh, options.eye_direction);
  const clay::render::Image image = clay::render::render_mesh(mesh, options, surfaces, drawn);
  const double ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  clay::render::write_png(image, png);
  std::printf("%s: %zu surface(s), %zu curve(s) -> %s (%d x %d, %.0f ms)\n", file.string().c_str(),
              surfaces.size(), drawn.size(), png.string().c_str(), image.width, image.height, ms);
  return 0;
}

/// clayform studio: the recipe (or a STEP/IGES model, or an empty recipe) behind the studio's
/// server until Ctrl-C. The history is autosaved beside the recipe; an autosave found there is
/// continued (--fresh sets it aside), so a crash or Ctrl-C loses no edit.
int studio(const std::string& recipe, int port, bool fresh) {
  namespace rc = clay::recipe;
  rc::StudioSession session =
      recipe.empty()
          ? rc::StudioSession(R"({"format": "clayform.recipe", "version": 1, "name": "untitled"})",
                              ".", "untitled")
          : rc::StudioSession::open(recipe);
  // Beside the recipe (or the model), named after the session's recipe.
  const fs::path autosave = rc::StudioSession::autosave_file(
      recipe.empty() ? fs::path(".") : fs::path(recipe).parent_path(), session.name());
  std::error_code ec;
  if (fs::exists(autosave, ec)) {
    if (fresh) {
      fs::rename(autosave, autosave.string() + ".old", ec);
      if (ec)
        throw clay::Error(
            clay::ErrorCategory::Io,
            "cannot set the autosave \"" + autosave.string() + "\" aside: " + ec.message());
      std::printf("Set the autosave aside as %s.old\n", autosave.string().c_str());
    } else {
      const std::string opened = session.text();
      const std::size_t entries = session.restore(autosave);
      if (entries == 1 && session.text() == opened)  // nothing was done since: start afresh
        session = recipe.empty() ? rc::StudioSession(opened, ".", "untitled")
                                 : rc::StudioSession::open(recipe);
      else
        std::printf(
            "Continuing the autosave %s (%zu history entries; --fresh starts from the "
            "recipe file instead)\n",
            autosave.string().c_str(), entries);
    }
  }
  session.autosave_to(autosave);
  // Ctrl-C and SIGTERM stop the server cleanly (the autosave written): they are taken by this
  // thread alone (sigwait), blocked before the server's threads start so they inherit the mask.
  sigset_t stops;
  sigemptyset(&stops);
  sigaddset(&stops, SIGINT);
  sigaddset(&stops, SIGTERM);
  pthread_sigmask(SIG_BLOCK, &stops, nullptr);
  rc::StudioOptions o;
  o.port = port;
  o.front_end = rc::viewer_dir();
  rc::StudioServer server(std::move(session), o);
  std::printf(
      "Clayform Studio at %s (open this address: it holds the session's token; "
      "autosave %s; Ctrl-C to stop)\n",
      server.url().c_str(), autosave.string().c_str());
  std::fflush(stdout);
  server.start();
  int signal_number = 0;
  sigwait(&stops, &signal_number);
  server.stop();
  std::printf("Clayform Studio stopped; the history is in %s\n", autosave.string().c_str());
  return 0;
}

}  // namespace

/// clayform sweep: replaces this process with `python3 -m clayform.sweeps SPEC --out OUT ...`
/// (its exit code is the command's: 0 all variants done, 1 some failed, 2 a bad description, a
/// storage error or a folder another sweep holds, 128 + N stopped by signal N; docs/sweeps.md).
int run_sweep(const std::string& spec, const std::string& out, const std::string& executor,
              int workers, const std::string& scheduler) {
#ifdef CLAYFORM_PYTHON_EXE
  const fs::path build_tree = CLAYFORM_PYTHON_BUILD_DIR;
  if (fs::exists(build_tree / "clayform" / "__init__.py")) {
    const char* old = std::getenv("PYTHONPATH");
    const std::string path = build_tree.string() + (old && *old ? ":" + std::string(old) : "");
    ::setenv("PYTHONPATH", path.c_str(), 1);
  }
  std::vector<std::string> args = {CLAYFORM_PYTHON_EXE,
                                   "-m",
                                   "clayform.sweeps",
                                   spec,
                                   "--out",
                                   out,
                                   "--executor",
                                   executor,
                                   "--workers",
                                   std::to_string(workers)};
  if (!scheduler.empty()) args.insert(args.end(), {"--scheduler", scheduler});
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  std::fflush(stdout);
  ::execv(CLAYFORM_PYTHON_EXE, argv.data());
  throw clay::Error(clay::ErrorCategory::Io,
                    std::string("clayform sweep: cannot run ") + CLAYFORM_PYTHON_EXE + ": " +
                        std::strerror(errno) +
                        "; install python3 and the clayform package (scripts/demo.sh does)");
#else
  (void)spec, (void)out, (void)executor, (void)workers, (void)scheduler;
  throw clay::Error(clay::ErrorCategory::InvalidArgument,
                    "clayform sweep: this build has no Python package (CLAYFORM_BUILD_PYTHON "
                    "was OFF); build with -DCLAYFORM_BUILD_PYTHON=ON");
#endif
}

int main(int argc, char** argv) {
  CLI::App app{"clayform — NURBS surface styling kernel"};
  app.set_version_flag("--version", std::string("clayform ") + CLAYFORM_VERSION);
  app.require_subcommand(1);
  std::string file;
  auto* info_cmd = app.add_subcommand("info",
                                      "List the surfaces of a STEP or IGES file: degrees, "
                                      "control points, knots, rational, box, validity");
  info_cmd->add_option("FILE", file, "a .step/.stp or .igs/.iges file")->required();
  bool strict = false;
  const char* strict_help =
      "read as before issue #39's healing: pcurves outside their domains, gaps wider than the "
      "file's tolerances and misordered loops are listed as problems, not healed";
  info_cmd->add_flag("--strict", strict, strict_help);
  std::string recipe_file, out_dir, deformation;
  bool quiet = false, progress = false;
  auto* run_cmd = app.add_subcommand(
      "run",
      "Run a recipe: build, deform and export every surface; writes NAME.step/.igs/.glb and "
      "report.json into --out only when every step succeeded");
  run_cmd->add_option("RECIPE", recipe_file, "a recipe (.json, docs/recipe.md)")->required();
  run_cmd->add_option("--out", out_dir, "output folder (created when missing)")->required();
  run_cmd->add_flag("--quiet", quiet, "no progress lines");
  run_cmd->add_flag("--progress", progress, "progress lines even when stdout is not a terminal");
  std::string profile;
  run_cmd->add_option("--profile", profile,
                      "write every export for this receiver: exact, opencascade, catia, class_a "
                      "or bicubic (default: each export's own \"profile\")");
  auto* validate_cmd = app.add_subcommand(
      "validate",
      "Check a recipe without running it: every problem at once, with its JSON path (and "
      "line and column for syntax errors)");
  validate_cmd->add_option("RECIPE", recipe_file, "a recipe (.json)")->required();
  auto* deform_cmd =
      app.add_subcommand("deform",
                         "Deform the whole model of a STEP or IGES file (trimmed faces, solids, "
                         "assembly) by a recipe's deformation stack; writes "
                         "STEM.step/.igs (as the recipe's first export says) and report.json into "
                         "--out, each read back and checked");
  deform_cmd->add_option("FILE", file, "a .step/.stp or .igs/.iges file")->required();
  deform_cmd->add_option("--recipe", recipe_file, "the recipe holding the deformation stack")
      ->required();
  deform_cmd->add_option("--out", out_dir, "output folder (created when missing)")->required();
  deform_cmd->add_option("--deformation", deformation,
                         "which stack (needed when the recipe has several)");
  bool allow_fold = false;
  deform_cmd->add_flag("--allow-fold", allow_fold,
                       "deform by a lattice not proven fold-free (the solid may intersect "
                       "itself); refused otherwise");
  deform_cmd->add_option("--profile", profile,
                         "write the model for this receiver: exact, opencascade, catia, class_a "
                         "or bicubic; the faces it would not take are refitted to it with their "
                         "edges (default: none, faces above degree 25 refitted)");
  deform_cmd->add_flag("--strict", strict, strict_help);
  deform_cmd->add_flag("--quiet", quiet, "no progress lines");
  deform_cmd->add_flag("--progress", progress, "progress lines even when stdout is not a terminal");
  // clayform render
  std::string png_file;
  std::vector<double> eye;
  clay::render::RenderOptions render_options;
  auto* render_cmd = app.add_subcommand(
      "render",
      "Write a PNG picture of the model of a STEP or IGES file (trimmed faces, holes are "
      "holes, in the file's colours), or of what a recipe builds with its curves drawn over "
      "it: orthographic view fitted to the model, shading with a soft highlight");
  render_cmd->add_option("FILE", file, "a .step/.stp or .igs/.iges file, or a recipe (.json)")
      ->required();
  bool no_curves = false;
  render_cmd->add_flag("--no-curves", no_curves, "a recipe: do not draw its curves");
  render_cmd->add_option("--png", png_file, "the picture to write (.png)")->required();
  render_cmd->add_option("--width", render_options.width, "picture width in pixels [16, 4096]")
      ->capture_default_str();
  render_cmd->add_option("--height", render_options.height, "picture height in pixels [16, 4096]")
      ->capture_default_str();
  render_cmd
      ->add_option(
          "--eye", eye,
          "direction from the model towards the eye, X Y Z (default -1 -1.2 0.9, turned to "
          "face an open panel's front)")
      ->expected(3);
  clay::brep::MeshOptions mesh_options;
  render_cmd
      ->add_option("--deflection", mesh_options.relative_deflection,
                   "mesh: largest distance from a triangle to its face, as a fraction of the "
                   "model's size [1e-6, 0.1]")
      ->capture_default_str();
  render_cmd->add_flag("--net", render_options.control_net, "draw the control nets");
  // clayform view / snapshot (clay/serve.hpp)
  std::string run_dir, host = "127.0.0.1";
  int port = 8765;
  auto* view_cmd = app.add_subcommand(
      "view",
      "Serve a run folder to the browser viewer: open the printed address (the folder needs the "
      "view/ data every run writes, and the viewer's build, viewer/dist or $CLAYFORM_VIEWER_DIR)");
  view_cmd->add_option("DIR", run_dir, "the --out folder of clayform run or deform")->required();
  view_cmd->add_option("--port", port, "TCP port, 0 for any free one")->capture_default_str();
  view_cmd->add_option("--host", host, "address to listen on")->capture_default_str();
  clay::recipe::SnapshotOptions snapshot_options;
  auto* snapshot_cmd = app.add_subcommand(
      "snapshot", "Write a PNG picture of the viewer's page on a run folder (headless chromium)");
  snapshot_cmd->add_option("DIR", run_dir, "the --out folder of clayform run or deform")
      ->required();
  snapshot_cmd->add_option("--png", png_file, "the picture to write (.png)")->required();
  snapshot_cmd->add_option("--width", snapshot_options.width, "picture width in pixels [16, 8192]")
      ->capture_default_str();
  snapshot_cmd
      ->add_option("--height", snapshot_options.height, "picture height in pixels [16, 8192]")
      ->capture_default_str();
  snapshot_cmd->add_flag("--bare", snapshot_options.bare,
                         "the picture alone, without toolbar and panels");
  snapshot_cmd
      ->add_option("--mode", snapshot_options.mode, "shaded, zebra, gaussian, mean or deviation")
      ->capture_default_str();
  snapshot_cmd
      ->add_option("--eye", snapshot_options.eye,
                   "direction from the model towards the eye, X Y Z (default: the viewer's)")
      ->expected(3);
  snapshot_cmd->add_option("--hide", snapshot_options.hide,
                           "a surface not to show, by name (repeat for more)");
  snapshot_cmd
      ->add_option("--stage", snapshot_options.stage,
                   "after, or before: the surfaces before their first deformation step")
      ->capture_default_str();
  // clayform studio (clay/studio.hpp): the recipe behind a WebSocket on 127.0.0.1.
  std::string studio_recipe;
  int studio_port = 8770;
  auto* studio_cmd = app.add_subcommand(
      "studio",
      "Serve a recipe to Clayform Studio on 127.0.0.1 and print its address: the kernel behind "
      "one WebSocket (/ws), every edit appended to the recipe's history (docs/studio.md)");
  studio_cmd->add_option("RECIPE", studio_recipe,
                         "a recipe (.json), or a STEP/IGES model to start one from; none: an "
                         "empty recipe");
  studio_cmd->add_option("--port", studio_port, "TCP port, 0 for any free one")
      ->capture_default_str();
  bool studio_fresh = false;
  studio_cmd->add_flag("--fresh", studio_fresh,
                       "start from the recipe file, setting aside its autosave (renamed to "
                       "NAME.studio-autosave.json.old) instead of continuing it");
  // clayform sweep: the Python package's sweeps (docs/sweeps.md), run by Debian's python3.
  std::string sweep_spec, executor = "local", scheduler;
  int workers = 2;
  auto* sweep_cmd = app.add_subcommand(
      "sweep",
      "Run every variant of a sweep description (docs/sweeps.md): each variant's STEP, IGES, "
      "glTF and report into OUT/<id>, OUT/index.csv and .jsonl, OUT/contact_sheet.png; a re-run "
      "skips finished variants");
  sweep_cmd->add_option("SPEC", sweep_spec, "a sweep description (.json)")->required();
  sweep_cmd->add_option("--out", out_dir, "output folder (created when missing)")->required();
  sweep_cmd->add_option("--executor", executor, "local (processes) or dask")
      ->check(CLI::IsMember({"local", "dask"}))
      ->capture_default_str();
  sweep_cmd->add_option("--workers", workers, "processes, or Dask workers of a LocalCluster")
      ->check(CLI::Range(1, 1024))
      ->capture_default_str();
  sweep_cmd->add_option("--scheduler", scheduler,
                        "an existing Dask scheduler, e.g. tcp://HOST:8786 (implies dask)");
  app.footer(
      "Exit codes: 0 success, 1 usage, 2 invalid argument, 3 invalid geometry or out of domain, "
      "4 degree limit, 5 file I/O, 6 exchange (STEP/IGES), 7 document problems (a recipe, stack or "
      "autosave), 8 tolerance not met, "
      "70 internal error.");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    // --help and --version exit 0; every usage error 1 (CLI11's own codes vary by error kind).
    return app.exit(e) == 0 ? 0 : 1;
  }
  try {
    if (*info_cmd) return info(file, strict);
    if (*sweep_cmd) return run_sweep(sweep_spec, out_dir, executor, workers, scheduler);
    if (*studio_cmd) return studio(studio_recipe, studio_port, studio_fresh);
    if (*render_cmd) {
      if (!eye.empty()) render_options.eye_direction = {eye[0], eye[1], eye[2]};
      if (fs::path(file).extension() == ".json")
        return render_recipe(file, png_file, render_options, !eye.empty(), !no_curves);
      return render_picture(file, png_file, render_options, !eye.empty(), mesh_options);
    }
    if (*view_cmd) {
      clay::recipe::ServeOptions o;
      o.host = host;
      o.port = port;
      clay::recipe::ViewServer server(run_dir, o);
      std::printf("Serving %s at %s (Ctrl-C to stop)\n", run_dir.c_str(), server.url().c_str());
      std::fflush(stdout);
      server.run();
      return 0;
    }
    if (*snapshot_cmd) {
      const auto start = std::chrono::steady_clock::now();
      clay::recipe::snapshot(run_dir, png_file, snapshot_options);
      const double s =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      std::printf("%s: %s view -> %s (%d x %d, %.1f s)\n", run_dir.c_str(),
                  snapshot_options.mode.c_str(), png_file.c_str(), snapshot_options.width,
                  snapshot_options.height, s);
      return 0;
    }
    const bool show = !quiet && (progress || ::isatty(STDOUT_FILENO));
    if (*validate_cmd) return validate(recipe_file);
    if (*run_cmd) {
      const auto recipe = clay::recipe::load_recipe(recipe_file);
      if (!profile.empty()) clay::deform::receiver_profile(profile);  // a typo fails at once
      auto options = run_options(show);
      options.profile = profile;
      auto result = clay::recipe::run_recipe(recipe, options);
      return finish(result, out_dir);
    }
    if (*deform_cmd)
      return deform_model_file(file, recipe_file, deformation, out_dir, show, allow_fold, profile,
                               strict);
  } catch (const clay::Error& e) {
    std::fprintf(stderr, "clayform: %s\n", e.what());
    return exit_code(e.category());
  } catch (const std::exception& e) {  // a bug, never a crash: say so and exit with Internal
    std::fprintf(stderr, "clayform: internal error: %s; please report it with the input\n",
                 e.what());
    return exit_code(clay::ErrorCategory::Internal);
  }
  return 0;
}
