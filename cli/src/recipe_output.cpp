// The outputs of a run: STEP, IGES and glTF per export, read back and checked, and report.json —
// written into a temporary folder and moved into place only when everything succeeded.
#include <clay/error.hpp>
#include <clay/recipe/recipe.hpp>
#include <clay/recipe/view.hpp>
#include <clay/surface/exchange.hpp>

#include <nlohmann/json.hpp>

#include <unistd.h>
#include <fstream>
#include <limits>
#include <system_error>

namespace clay::recipe {

namespace {

using Json = nlohmann::ordered_json;
namespace fs = std::filesystem;

Json figure_json(const Figure& f) {
  return std::visit([](const auto& x) { return Json(x); }, f);
}

}  // namespace

std::string report_json(const RunResult& result) {
  Json j = Json::object();
  j["format"] = "clayform.report";
  j["version"] = 1;
  j["recipe"] = result.recipe;
#ifdef CLAYFORM_VERSION
  j["clayform"] = CLAYFORM_VERSION;
#endif
  bool warnings = false;
  Json steps = Json::array();
  for (const auto& s : result.steps) {
    Json x = Json::object();
    x["path"] = s.path;
    x["kind"] = s.kind;
    x["seconds"] = s.seconds;
    x["warning"] = s.warning;
    x["message"] = s.message;
    Json figures = Json::object();
    for (const auto& [name, value] : s.figures) figures[name] = figure_json(value);
    x["figures"] = std::move(figures);
    warnings = warnings || s.warning;
    steps.push_back(std::move(x));
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
    if (e.checked) {
      x["valid"] = e.valid;
      x["read_back_identical"] = e.read_back_identical;
      x["problems"] = e.problems;
    }
    exports.push_back(std::move(x));
  }
  j["exports"] = std::move(exports);
  return j.dump(2) + "\n";
}

std::vector<fs::path> write_outputs(RunResult& result, const fs::path& out_dir) {
  if (out_dir.empty())
    throw Error(ErrorCategory::InvalidArgument, "write_outputs: give an output folder");
  const fs::path target = fs::absolute(out_dir).lexically_normal();
  const fs::path parent =
      target.has_filename() ? target.parent_path() : target.parent_path().parent_path();
  const std::string leaf =
      target.has_filename() ? target.filename().string() : target.parent_path().filename().string();
  std::error_code ec;
  fs::create_directories(parent, ec);
  if (ec)
    throw Error(ErrorCategory::Io, "cannot create the folder \"" + parent.string() +
                                       "\": " + ec.message() + "; check the path and permissions");
  const fs::path tmp = parent / ("." + leaf + ".clayform-" + std::to_string(::getpid()));
  fs::remove_all(tmp, ec);
  fs::create_directory(tmp, ec);
  if (ec)
    throw Error(ErrorCategory::Io,
                "cannot create the temporary folder \"" + tmp.string() + "\": " + ec.message());
  std::vector<std::string> names;
  try {
    for (auto& e : result.exports) {
      e.files.clear();
      for (const auto& format : e.formats) {
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
    {
      std::ofstream out(tmp / "report.json", std::ios::binary);
      out << report_json(result);
      if (!out)
        throw Error(ErrorCategory::Io, "cannot write \"" + (tmp / "report.json").string() + "\"");
    }
    names.push_back("report.json");
    write_view_data(result, tmp);  // view/manifest.json and view/NNN.bin (clay/recipe/view.hpp)
    fs::create_directories(target, ec);
    if (ec)
      throw Error(ErrorCategory::Io,
                  "cannot create the output folder \"" + target.string() + "\": " + ec.message());
    std::vector<fs::path> written;
    for (const auto& n : names) {
      fs::rename(tmp / n, target / n, ec);  // same file system: atomic per file
      if (ec)
        throw Error(ErrorCategory::Io,
                    "cannot move \"" + n + "\" into \"" + target.string() + "\": " + ec.message());
      written.push_back(target / n);
    }
    // The view folder as a whole: a previous run's meshes go, this run's come in one rename.
    fs::remove_all(target / "view", ec);
    if (ec)
      throw Error(ErrorCategory::Io,
                  "cannot replace \"" + (target / "view").string() + "\": " + ec.message());
    fs::rename(tmp / "view", target / "view", ec);
    if (ec)
      throw Error(ErrorCategory::Io,
                  "cannot move \"view\" into \"" + target.string() + "\": " + ec.message());
    written.push_back(target / "view");
    fs::remove_all(tmp, ec);
    return written;
  } catch (...) {
    fs::remove_all(tmp, ec);
    throw;
  }
}

}  // namespace clay::recipe
