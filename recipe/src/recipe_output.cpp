// The outputs of a run: STEP, IGES and glTF per export, read back and checked, and report.json —
// written into a temporary folder and moved into place only when everything succeeded.
#include "report_json.hpp"

#include <clay/cancel.hpp>
#include <clay/error.hpp>
#include <clay/internal/files.hpp>
#include <clay/occt/model_exchange.hpp>
#include <clay/occt/surface_exchange.hpp>
#include <clay/recipe/recipe.hpp>
#include <clay/recipe/view.hpp>

#include <nlohmann/json.hpp>

#include <algorithm>

#include <unistd.h>
#include <cerrno>
#include <cstring>
#include <fstream>
#include <limits>
#include <system_error>

namespace clay::recipe {

namespace {

using Json = nlohmann::ordered_json;
namespace fs = std::filesystem;

using detail::figure_json;

Json model_figures(const ModelRunResult& r);

/// The first keys of every report: format, version, recipe and the clayform that wrote it.
Json report_header(const std::string& recipe) {
  Json j = Json::object();
  j["format"] = "clayform.report";
  j["version"] = 1;
  j["recipe"] = recipe;
#ifdef CLAYFORM_VERSION
  j["clayform"] = CLAYFORM_VERSION;
#endif
  return j;
}

}  // namespace

std::string report_json(const RunResult& result) {
  Json j = report_header(result.recipe);
  bool warnings = false;
  Json steps = Json::array();
  for (const auto& s : result.steps) {
    warnings = warnings || s.warning;
    steps.push_back(detail::step_json(s));
  }
  j["ok"] = true;  // a run that throws writes no report
  j["warnings"] = warnings;
  j["seconds"] = result.seconds;
  j["steps"] = std::move(steps);
  Json exports = Json::array();
  for (const auto& e : result.exports) {
    Json x = Json::object();
    x["name"] = e.name;
    x["surfaces"] = e.surface_names;
    x["files"] = e.files;
    long points = 0;
    int degree = 0;
    Json sizes = Json::array();
    for (const auto& s : e.surfaces) {
      points += s.points.rows();
      degree = std::max({degree, s.u.degree, s.v.degree});
      sizes.push_back({{"degree_u", s.u.degree},
                       {"degree_v", s.v.degree},
                       {"count_u", s.count_u()},
                       {"count_v", s.count_v()},
                       {"rational", s.is_rational()}});
    }
    x["patches"] = e.surfaces.size();
    x["control_points"] = points;
    x["degree"] = degree;
    x["sizes"] = std::move(sizes);
    x["profile"] = e.profile;
    // Per surface, how far it may be from the all-exact recipe (mm; null: not bounded).
    Json bounds = Json::array();
    for (double b : e.bounds_mm) bounds.push_back(std::isfinite(b) ? Json(b) : Json(nullptr));
    x["bounds_mm"] = std::move(bounds);
    if (e.checked) {
      x["valid"] = e.valid;
      x["read_back_identical"] = e.read_back_identical;
      x["problems"] = e.problems;
    }
    exports.push_back(std::move(x));
  }
  j["exports"] = std::move(exports);
  if (!result.models.empty()) {
    Json models = Json::array();
    for (const auto& m : result.models) {
      Json x = Json::object();
      x["name"] = m.name;
      x["import"] = m.source;
      x["deformation"] = m.deformation;
      x["bodies"] = m.bodies;
      x["faces"] = m.faces;
      x["files"] = m.files;
      if (!m.files.empty()) x["valid"] = m.valid;
      x["seconds"] = m.seconds;
      x["model"] = model_figures(m);
      models.push_back(std::move(x));
    }
    j["models"] = std::move(models);
  }
  return j.dump(2) + "\n";
}

namespace {

/// The output folder and its temporary sibling, where everything is written first.
struct Staging {
  fs::path target, tmp;
};

Staging stage(const fs::path& out_dir, std::string_view caller) {
  if (out_dir.empty())
    throw Error(ErrorCategory::InvalidArgument, std::string(caller) + ": give an output folder");
  Staging s;
  s.target = fs::absolute(out_dir).lexically_normal();
  const fs::path parent =
      s.target.has_filename() ? s.target.parent_path() : s.target.parent_path().parent_path();
  const std::string leaf = s.target.has_filename() ? s.target.filename().string()
                                                   : s.target.parent_path().filename().string();
  std::error_code ec;
  fs::create_directories(parent, ec);
  if (ec)
    throw Error(ErrorCategory::Io, "cannot create the folder \"" + parent.string() +
                                       "\": " + ec.message() + "; check the path and permissions");
  // A folder of its own (mkdtemp): runs into the same folder at once, from threads or processes,
  // never share one (they did with a name from the process id, issue #36).
  std::string pattern = (parent / ("." + leaf + ".clayform-XXXXXX")).string();
  if (!::mkdtemp(pattern.data()))
    throw Error(ErrorCategory::Io, "cannot create a temporary folder beside \"" +
                                       s.target.string() + "\": " + std::strerror(errno) +
                                       "; check the folder's permissions and free space");
  s.tmp = pattern;
  return s;
}

/// Moves the named files from the temporary folder into the target (created when missing).
std::vector<fs::path> move_in(const Staging& s, const std::vector<std::string>& names) {
  std::error_code ec;
  fs::create_directories(s.target, ec);
  if (ec)
    throw Error(ErrorCategory::Io,
                "cannot create the output folder \"" + s.target.string() + "\": " + ec.message());
  std::vector<fs::path> written;
  for (const auto& n : names) {
    fs::rename(s.tmp / n, s.target / n, ec);  // same file system: atomic per file
    if (ec)
      throw Error(ErrorCategory::Io,
                  "cannot move \"" + n + "\" into \"" + s.target.string() + "\": " + ec.message());
    written.push_back(s.target / n);
  }
  return written;
}

/// Moves the view folder from the temporary folder into the target as a whole: a previous run's
/// meshes go, this run's come in one rename. The previous one is first renamed into this run's
/// staging folder (removed with it), so runs into one folder at once never see a half-removed
/// view, and one that lands between the two renames is moved aside again. Returns its path.
fs::path move_view_in(const Staging& s) {
  const fs::path view = s.target / "view";
  std::error_code ec;
  for (int attempt = 0; attempt < 16; ++attempt) {
    fs::rename(view, s.tmp / ("old-view-" + std::to_string(attempt)), ec);
    if (ec && ec != std::errc::no_such_file_or_directory)
      throw Error(ErrorCategory::Io, "cannot replace \"" + view.string() + "\": " + ec.message());
    fs::rename(s.tmp / "view", view, ec);
    if (!ec) return view;
    if (ec != std::errc::directory_not_empty && ec != std::errc::file_exists) break;
  }
  throw Error(ErrorCategory::Io,
              "cannot move \"view\" into \"" + s.target.string() + "\": " + ec.message());
}

void write_text(const fs::path& file, const std::string& text) {
  std::ofstream out(file, std::ios::binary);
  out << text;
  if (!out) throw Error(ErrorCategory::Io, "cannot write \"" + file.string() + "\"");
}

Json write_model_files(const ModelRunResult& result, const Staging& staging, std::string_view stem,
                       std::vector<std::string>& names);

}  // namespace

std::vector<fs::path> write_outputs(RunResult& result, const fs::path& out_dir) {
  const Staging staging = stage(out_dir, "write_outputs");
  const fs::path& target = staging.target;
  const fs::path& tmp = staging.tmp;
  std::error_code ec;
  std::vector<std::string> names;
  try {
    // Every file stem a plain name: nothing is written outside the output folder.
    for (const auto& e : result.exports)
      internal::check_file_name(e.name, "write_outputs: the export");
    for (const auto& m : result.models)
      internal::check_file_name(m.name, "write_outputs: the model");
    for (auto& e : result.exports) {
      e.files.clear();
      for (const auto& format : e.formats) {
        throw_if_cancelled("writing a recipe's files");  // (the staging folder is removed)
        const std::string file = e.name + (format == "step"   ? ".step"
                                           : format == "iges" ? ".igs"
                                                              : ".glb");
        if (format == "step") {
          surface::StepWriteOptions o;
          o.schema = e.schema == "AP242" ? surface::StepSchema::AP242 : surface::StepSchema::AP214;
          o.product_name = e.name;
          surface::write_step(e.surfaces, tmp / file, o);
        } else if (format == "iges") {
          surface::write_iges(e.surfaces, tmp / file);
        } else {
          surface::write_gltf(e.surfaces, tmp / file);
        }
        e.files.push_back(file);
        names.push_back(file);
      }
      // Read back what a CAD system will read (STEP first) and check it.
      const bool has_step =
          std::find(e.formats.begin(), e.formats.end(), "step") != e.formats.end();
      const bool has_iges =
          std::find(e.formats.begin(), e.formats.end(), "iges") != e.formats.end();
      if (has_step || has_iges) {
        const auto back = has_step ? surface::read_step(tmp / (e.name + ".step"))
                                   : surface::read_iges(tmp / (e.name + ".igs"));
        const auto check = surface::check_faces(back);
        e.checked = true;
        e.valid = check.valid;
        e.problems = check.problems;
        e.read_back_identical = back.size() == e.surfaces.size();
        for (std::size_t k = 0; e.read_back_identical && k < back.size(); ++k)
          e.read_back_identical = surface::identical(back[k], e.surfaces[k]);
        // Checked here, before anything is moved into `out_dir`: an export that reads back
        // invalid fails the run, and a failed run leaves nothing behind (it used to leave all its
        // files and report the failure afterwards, issue #18).
        if (!e.valid) {
          std::string m = "export " + e.name + ": " +
                          (has_step ? e.name + ".step" : e.name + ".igs") +
                          " reads back INVALID (BRepCheck), so nothing was written to \"" +
                          target.string() + "\"";
          for (const auto& p : e.problems) m += "\n  problem: " + p;
          throw Error(ErrorCategory::Exchange, m);
        }
      }
    }
    for (auto& m : result.models) {
      throw_if_cancelled("writing a recipe's files");
      std::vector<std::string> files;
      write_model_files(m, staging, m.name, files);
      m.files = files;
      m.valid = true;  // write_model_files refuses a file that does not read back valid
      names.insert(names.end(), files.begin(), files.end());
    }
    write_text(tmp / "report.json", report_json(result));
    names.push_back("report.json");
    write_view_data(result, tmp);  // view/manifest.json and view/NNN.bin (clay/recipe/view.hpp)
    std::vector<fs::path> written = move_in(staging, names);
    written.push_back(move_view_in(staging));
    fs::remove_all(tmp, ec);
    return written;
  } catch (...) {
    fs::remove_all(tmp, ec);
    throw;
  }
}

namespace {

/// A model run's figures: its topology and what the deformation did (report.json "model").
Json model_figures(const ModelRunResult& r) {
  const auto& m = r.report;
  const brep::Counts& c = m.counts;
  Json model = Json::object();
  model["bodies"] = c.bodies;
  model["solids"] = c.solids;
  model["shells"] = c.shells;
  model["faces"] = c.faces;
  model["trimmed_faces"] = c.trimmed_faces;
  model["inner_loops"] = c.inner_loops;
  model["edges"] = c.edges;
  model["vertices"] = c.vertices;
  if (c.wires > 0) {
    model["wires"] = c.wires;
    model["wire_edges"] = c.wire_edges;
  }
  model["faces_exact"] = m.faces_exact;
  model["faces_refit"] = m.faces_refit;
  model["faces_untouched"] = m.faces_untouched;
  if (!m.profile.empty()) {
    model["profile"] = m.profile;
    model["faces_elevated"] = m.faces_elevated;
  }
  model["edges_exact"] = m.edges_exact;
  model["edges_refit"] = m.edges_refit;
  model["edges_untouched"] = m.edges_untouched;
  model["max_certified_bound_mm"] = m.max_certified_bound_mm;
  model["max_edge_gap_mm"] = m.max_edge_gap_mm;
  model["max_deviation_mm"] = m.max_deviation_mm;
  model["volume_before_mm3"] = m.volume_before_mm3;
  model["volume_after_mm3"] = m.volume_after_mm3;
  model["solids_reversed"] = m.solids_reversed;
  if (m.volume_ratio_bounded) {
    model["volume_ratio_min"] = m.volume_ratio_min;
    model["volume_ratio_max"] = m.volume_ratio_max;
  }
  model["fold_free"] = r.fold_free;
  if (!r.kept.empty()) {
    Json kept = Json::array();
    for (const ModelRunResult::Kept& k : r.kept) {
      auto has = [&](const char* p) {
        return std::find(k.properties.begin(), k.properties.end(), p) != k.properties.end();
      };
      Json entry = {{"step", k.step},
                    {"properties", k.properties},
                    {"newton_steps", k.iterations},
                    {"largest_correction_mm", k.largest_correction_mm}};
      if (has("volume") || has("centroid")) {  // measured only when kept
        entry["volume_before_mm3"] = k.volume_before_mm3;
        entry["volume_after_mm3"] = k.volume_after_mm3;
        entry["centroid_shift_mm"] = k.centroid_shift_mm;
      }
      if (has("area")) {
        entry["area_before_mm2"] = k.area_before_mm2;
        entry["area_after_mm2"] = k.area_after_mm2;
      }
      kept.push_back(entry);
    }
    model["kept"] = kept;
  }
  model["continuity"] = detail::continuity_json(m.continuity_before, m.continuity_after);
  model["message"] = m.brief();
  return model;
}

Json model_report_json(const ModelRunResult& r, const Json& exports) {
  Json j = report_header(r.recipe);
  j["ok"] = true;
  j["seconds"] = r.seconds;
  j["deformation"] = r.deformation;
  j["model"] = model_figures(r);
  j["exports"] = exports;
  return j;
}

/// Writes the model's files (STEM.step, STEM.igs, STEM.glb per result.formats) into the staging
/// folder, each
/// STEP and IGES file read back (read_model) and checked (BRepCheck, the same counts) first;
/// appends their names to `names` and returns what the report says of each.
Json write_model_files(const ModelRunResult& result, const Staging& staging, std::string_view stem,
                       std::vector<std::string>& names) {
  const fs::path& tmp = staging.tmp;
  Json exports = Json::array();
  const brep::Counts counts = brep::counts(result.model);
  for (const auto& format : result.formats) {
    const std::string file = std::string(stem) + (format == "step"   ? ".step"
                                                  : format == "iges" ? ".igs"
                                                                     : ".glb");
    brep::ModelWriteOptions o;
    o.schema = result.schema == "AP242" ? surface::StepSchema::AP242 : surface::StepSchema::AP214;
    if (format == "glb") {  // a preview: the same shapes, meshed; nothing to read back
      o.check = false;
      brep::write_model(result.model, tmp / file, o);
      Json x = Json::object();
      x["name"] = std::string(stem);
      x["file"] = file;
      x["preview"] = true;
      exports.push_back(std::move(x));
      names.push_back(file);
      continue;
    }
    const brep::ModelCheck written = brep::write_model(result.model, tmp / file, o);
    // Read back as a CAD system would, and checked before anything moves into out_dir.
    const brep::ImportedModel back = brep::read_model(tmp / file);
    const bool same = back.report.counts.faces == counts.faces &&
                      back.report.counts.edges == counts.edges &&
                      back.report.counts.solids == counts.solids &&
                      back.report.counts.vertices == counts.vertices;
    if (!written.valid || !back.report.problems.empty() || !same) {
      std::string m = file + " reads back " +
                      (!written.valid ? std::string("INVALID (BRepCheck)")
                       : !same        ? "with other counts (" + back.report.brief() + ")"
                                      : "broken") +
                      ", so nothing was written to \"" + staging.target.string() + "\"";
      for (const auto& p : written.problems) m += "\n  problem: " + p;
      for (const auto& p : back.report.problems) m += "\n  problem: " + p;
      throw Error(ErrorCategory::Exchange, m);
    }
    Json x = Json::object();
    x["name"] = std::string(stem);
    x["file"] = file;
    x["valid"] = written.valid;
    x["volume_mm3"] = written.volume_mm3;
    x["read_back"] = back.report.brief();
    exports.push_back(std::move(x));
    names.push_back(file);
  }
  return exports;
}

}  // namespace

std::vector<fs::path> write_model_outputs(const ModelRunResult& result, const fs::path& out_dir,
                                          std::string_view stem) {
  const Staging staging = stage(out_dir, "write_model_outputs");
  std::error_code ec;
  try {
    std::vector<std::string> names;
    const Json exports = write_model_files(result, staging, stem, names);
    write_text(staging.tmp / "report.json", model_report_json(result, exports).dump(2));
    names.push_back("report.json");
    // The view folder (clayform view): the model as the one entry of a run's models.
    RunResult run;
    run.recipe = result.recipe;
    run.models.push_back(result);
    run.models.back().name = std::string(stem);
    write_view_data(run, staging.tmp);
    std::vector<fs::path> written = move_in(staging, names);
    written.push_back(move_view_in(staging));
    fs::remove_all(staging.tmp, ec);
    return written;
  } catch (...) {
    fs::remove_all(staging.tmp, ec);
    throw;
  }
}

}  // namespace clay::recipe
