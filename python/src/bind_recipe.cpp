// Recipes: load or parse, check, run in memory (the GIL released), write the outputs; reports
// as dicts. A recipe pickles as its text, its base folder and its name.
#include "common.hpp"

#include <clay/internal/files.hpp>
#include <clay/recipe/path.hpp>
#include <clay/recipe/recipe.hpp>

#include <pybind11/stl/filesystem.h>

#include <filesystem>
#include <fstream>
#include <sstream>

namespace clay::python {

py::tuple deform_model(const recipe::Recipe& r, const brep::Model& model,
                       const std::string& deformation, bool allow_fold,
                       const std::string& profile);  // bind_model.cpp

namespace {

namespace fs = std::filesystem;

/// A checked recipe and what made it: the text, the folder its imports are resolved in, its name.
struct PyRecipe {
  recipe::Recipe recipe;
  std::string text;
  std::string base_dir;
};

PyRecipe parse(const std::string& text, const std::string& base_dir, const std::string& name) {
  PyRecipe r;
  r.recipe = recipe::parse_recipe(text, base_dir, name);
  r.text = text;
  r.base_dir = base_dir;
  return r;
}

py::object figure(const recipe::Figure& f) {
  return std::visit([](const auto& v) -> py::object { return py::cast(v); }, f);
}

py::object report_dict(const recipe::RunResult& r) {
  return py::module_::import("json").attr("loads")(recipe::report_json(r));
}

}  // namespace

void bind_recipe(py::module_& m) {
  m.def(
      "recipe_path",
      [](const std::string& path) {
        py::list out;
        for (const recipe::PathStep& step : recipe::parse_path(path)) {
          if (const auto* key = std::get_if<std::string>(&step))
            out.append(py::str(*key));
          else
            out.append(py::int_(std::get<std::size_t>(step)));
        }
        return out;
      },
      py::arg("path"),
      "The steps of a recipe path ('a.b[2].c' -> ['a', 'b', 2, 'c']): the kernel's one grammar, "
      "shared by the studio's edits and the sweeps' parameters. InvalidArgumentError names the "
      "rule a malformed path breaks.");
  py::class_<recipe::RunResult>(m, "RunResult",
                                "What a recipe run computed, in memory: surfaces, curves, steps "
                                "and the report; write(out) writes the exports.")
      .def_property_readonly("name", [](const recipe::RunResult& r) { return r.recipe; })
      .def_property_readonly(
          "surfaces",
          [](const recipe::RunResult& r) {
            py::dict d;
            for (const auto& [name, s] : r.surfaces) d[py::str(name)] = s;
            return d;
          },
          "Every named surface (copies), by name.")
      .def_property_readonly(
          "curves",
          [](const recipe::RunResult& r) {
            py::dict d;
            for (const auto& [name, c] : r.curves) d[py::str(name)] = c;
            return d;
          },
          "Every named curve (copies), by name.")
      .def_property_readonly(
          "steps",
          [](const recipe::RunResult& r) {
            py::list out;
            for (const auto& s : r.steps) {
              py::dict d, figures;
              d["path"] = s.path;
              d["kind"] = s.kind;
              d["seconds"] = s.seconds;
              d["warning"] = s.warning;
              d["reused"] = s.reused;
              d["message"] = s.message;
              for (const auto& [k, v] : s.figures) figures[py::str(k)] = figure(v);
              d["figures"] = figures;
              out.append(d);
            }
            return out;
          },
          "Every step's report: path, kind, seconds, warning, reused (taken from a RunCache), "
          "message, figures.")
      .def_property_readonly("report", &report_dict, "The report as report.json holds it (a dict).")
      .def_property_readonly("seconds", [](const recipe::RunResult& r) { return r.seconds; })
      .def(
          "write",
          [](recipe::RunResult& r, const fs::path& out) {
            std::vector<fs::path> files;
            {
              py::gil_scoped_release free;
              files = recipe::write_outputs(r, out);
            }
            std::vector<std::string> names;
            for (const auto& f : files) names.push_back(f.string());
            return names;
          },
          py::arg("out"),
          "Writes every export (STEP, IGES, glTF), report.json and the view folder into out, "
          "atomically; returns the paths written.")
      .def("__repr__", [](const recipe::RunResult& r) {
        return "<clayform.RunResult '" + r.recipe + "': " + std::to_string(r.surfaces.size()) +
               " surfaces, " + std::to_string(r.steps.size()) + " steps>";
      });

  py::class_<recipe::RunCache, std::shared_ptr<recipe::RunCache>>(
      m, "RunCache",
      "The results of recipe steps kept from one run for the next (docs/recipe.md, run cache): "
      "pass the same cache to Recipe.run and a step whose definition and inputs did not change "
      "is taken, bit for bit, instead of run again. Thread-safe; the least recently used "
      "results go beyond capacity_bytes.")
      .def(py::init<std::size_t>(), py::arg("capacity_bytes") = std::size_t{256} << 20)
      .def_property_readonly(
          "counts",
          [](const recipe::RunCache& c) {
            const auto n = c.counts();
            py::dict d;
            d["reused"] = n.reused;
            d["kept"] = n.kept;
            d["evicted"] = n.evicted;
            d["entries"] = n.entries;
            d["bytes"] = n.bytes;
            d["fits_reused"] = n.fits_reused;
            return d;
          },
          "reused (steps taken), kept (results stored), evicted, entries and bytes held now, "
          "fits_reused (stroke fits taken).")
      .def("clear", &recipe::RunCache::clear, "Drops every kept result and zeroes the counts.")
      .def("__repr__", [](const recipe::RunCache& c) {
        const auto n = c.counts();
        return "<clayform.RunCache: " + std::to_string(n.entries) + " results, " +
               std::to_string(n.bytes) + " bytes>";
      });

  py::class_<PyRecipe>(m, "Recipe",
                       "A checked recipe (docs/recipe.md). Recipe.load(path) or "
                       "Recipe.parse(text); run() runs it; pickles as its text.")
      .def_static(
          "load",
          [](const fs::path& file) {
            return parse(internal::read_text(file, "recipe"), file.parent_path().string(),
                         file.stem().string());
          },
          py::arg("path"), "Reads and checks a recipe file (DocumentError lists every problem).")
      .def_static("parse", &parse, py::arg("text"), py::arg("base_dir") = "", py::arg("name") = "",
                  "Checks recipe text; imports are resolved in base_dir; name is used when the "
                  "text has none.")
      .def_static(
          "check",
          [](const std::string& text, const std::string& base_dir) {
            py::list out;
            for (const auto& p : recipe::check_recipe(text, base_dir)) {
              py::dict d;
              d["path"] = p.path;
              d["message"] = p.message;
              d["line"] = p.line;
              d["column"] = p.column;
              out.append(d);
            }
            return out;
          },
          py::arg("text"), py::arg("base_dir") = "",
          "Every problem of recipe text as dicts (path, message, line, column); [] when valid.")
      .def_property_readonly("name", [](const PyRecipe& r) { return r.recipe.name(); })
      .def_property_readonly("text", [](const PyRecipe& r) { return r.text; })
      .def_property_readonly("base_dir", [](const PyRecipe& r) { return r.base_dir; })
      .def_property_readonly("deformations",
                             [](const PyRecipe& r) { return r.recipe.deformation_names(); })
      .def_property_readonly("final_surfaces",
                             [](const PyRecipe& r) { return recipe::final_surfaces(r.recipe); })
      .def(
          "run",
          [](const PyRecipe& r, const std::optional<fs::path>& out,
             std::shared_ptr<recipe::RunCache> cache) {
            recipe::RunResult result;
            {
              py::gil_scoped_release free;
              recipe::RunOptions options;
              options.cache = std::move(cache);
              result = recipe::run_recipe(r.recipe, options);
            }
            if (out) {
              py::gil_scoped_release free;
              recipe::write_outputs(result, *out);
            }
            return result;
          },
          py::arg("out") = py::none(), py::kw_only(), py::arg("cache") = nullptr,
          "Runs every step in memory (the GIL released); with out, writes the exports, "
          "report.json and the view folder there as `clayform run --out` does. With cache (a "
          "RunCache), the steps it holds unchanged are taken from it and the others kept in it.")
      .def(
          "deform_model",
          [](const PyRecipe& r, const brep::Model& model, const std::string& deformation,
             bool allow_fold, const std::string& profile) {
            return deform_model(r.recipe, model, deformation, allow_fold, profile);
          },
          py::arg("model"), py::arg("deformation") = "", py::kw_only(),
          py::arg("allow_fold") = false, py::arg("profile") = "",
          "The model deformed by the recipe's stack (the one named, or its only one), as "
          "`clayform deform` does: (Model, report). A lattice not proven fold-free raises "
          "InvalidGeometryError (a folded solid intersects itself) unless allow_fold=True. "
          "profile: the receiver the model is written for (exact, opencascade, catia, class_a, "
          "bicubic; '' none): faces it would not take are refitted to it with their edges.")
      .def("__repr__",
           [](const PyRecipe& r) { return "<clayform.Recipe '" + r.recipe.name() + "'>"; })
      .def(py::pickle(
          [](const PyRecipe& r) { return py::make_tuple(r.text, r.base_dir, r.recipe.name()); },
          [](const py::tuple& t) {
            return parse(t[0].cast<std::string>(), t[1].cast<std::string>(),
                         t[2].cast<std::string>());
          }));
}

}  // namespace clay::python
