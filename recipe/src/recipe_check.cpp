// Recipe checking: JSON text → RecipeData, with every problem collected (docs/recipe.md). This
// file holds the document's walk, composition and exports, the syntax checks and the public
// entry points; the readers of the other sections are in recipe_check_*.cpp (recipe_checker.hpp).
#include "recipe_checker.hpp"
#include "run_cache.hpp"

#include <clay/recipe/document.hpp>

#include <clay/internal/files.hpp>

namespace clay::recipe {

namespace check_detail {

void RecipeChecker::rebuild(const std::string& name, const Json& j, const std::string& path) {
  names_.curves_declared.clear();
  sketch(name, j, path);
}

void RecipeChecker::run(const Json& root) {
  if (!c_.object(root, "",
                 {"format", "version", "name", "description", "units", "composition", "strokes",
                  "curves", "sketches", "surfaces", "deformations", "exports", "models"},
                 "a recipe {\"format\": \"clayform.recipe\", \"version\": 1, ...}"))
    return;
  const Json* format = c_.member(root, "", "format", true, "\"format\": \"clayform.recipe\"");
  if (format && (!format->is_string() || format->get<std::string>() != format_name))
    c_.add("format", "expected \"clayform.recipe\", found " + found(*format) +
                         "; this is not a Clayform recipe (a deformation stack file is read by "
                         "deform::stack_from_json)");
  const Json* version = c_.member(root, "", "version", true, "\"version\": 1");
  if (version && (!version->is_number_integer() || version->get<long long>() != format_version))
    c_.add("version", found(*version) + " is not supported: this clayform reads version " +
                          std::to_string(format_version) + "; write the recipe for version 1");
  if (const Json* j = c_.member(root, "", "name", false, "")) {
    data.name = c_.string(*j, "name").value_or("");
    // The name is the stem of files written for the recipe (the studio's export and autosave):
    // a name such as "../../x" wrote outside the output folder (issue #36).
    if (const auto problem = internal::file_name_problem(data.name); problem && j->is_string())
      c_.add("name", "the name \"" + internal::clip_utf8(data.name, 60) +
                         "\" is not a plain file name (" + *problem +
                         "); give a name such as \"hood_v2\"");
  }
  if (const Json* j = c_.member(root, "", "description", false, ""))
    data.description = c_.string(*j, "description").value_or("");
  if (const Json* j = c_.member(root, "", "units", false, "")) {
    const auto u = c_.string(*j, "units");
    if (u && *u != "mm")
      c_.add("units", "\"" + *u +
                          "\" is not supported: Clayform models are in millimetres; "
                          "convert the lengths and write \"units\": \"mm\"");
  }
  if (const Json* j = c_.member(root, "", "composition", false, ""))
    data.composition = composition(*j, "composition", Composition{});

  declare(root);
  section(root, "strokes",
          [&](const std::string& n, const Json& j, const std::string& p) { stroke(n, j, p); });
  section(root, "curves",
          [&](const std::string& n, const Json& j, const std::string& p) { curve(n, j, p); });
  section(root, "sketches",
          [&](const std::string& n, const Json& j, const std::string& p) { sketch(n, j, p); });
  section(root, "deformations",
          [&](const std::string& n, const Json& j, const std::string& p) { stack(n, j, p); });
  section(root, "surfaces",
          [&](const std::string& n, const Json& j, const std::string& p) { surface(n, j, p); });
  section(root, "exports",
          [&](const std::string& n, const Json& j, const std::string& p) { exporting(n, j, p); });
  section(root, "models",
          [&](const std::string& n, const Json& j, const std::string& p) { modelling(n, j, p); });
  // Curves taken from surfaces may need surfaces that need them: report the loop, once.
  if (const std::vector<std::string> cycle = dependency_cycle(data); !cycle.empty()) {
    std::string loop, where;
    for (const std::string& node : cycle) loop += (loop.empty() ? "" : " -> ") + node;
    for (const CurveDef& c : data.curves)
      if (where.empty() && c.from_surface() &&
          std::find(cycle.begin(), cycle.end(), "curve " + c.name) != cycle.end())
        where = c.path;
    c_.add(where.empty() ? "curves" : where,
           "definitions need each other (" + loop +
               "): take the curve from a surface that is built without it");
  }
}

void RecipeChecker::declare(const Json& root) {
  std::map<std::string, std::string> curve_owner;  // name → path of its definition
  auto declare_curve = [&](const std::string& name, const std::string& path) {
    const auto [it, inserted] = curve_owner.emplace(name, path);
    if (!inserted)
      c_.add(path, "the curve name \"" + name + "\" is already used by " + it->second +
                       "; strokes, curves and sketch entities share one namespace: rename one");
    names_.curves_declared.insert(name);
  };
  auto each = [&](std::string_view section_key, auto&& f) {
    const Json* s = c_.member(root, "", section_key, false, "");
    if (!s || !s->is_object() || s->size() > limit::entries) return;  // reported by section()
    for (const auto& [name, value] : s->items()) {
      const std::string path = key_path(std::string(section_key), name);
      if (!valid_name(name))
        c_.add(path, "the name \"" + name + "\" is not allowed; use 1 to 64 of A-Z a-z 0-9 _ -");
      f(name, value, path);
    }
  };
  each("strokes", [&](const std::string& n, const Json& v, const std::string& p) {
    const int pieces = declared_pieces(v);  // a stroke split at its corners: NAME.1 .. NAME.N
    if (pieces == 0) declare_curve(n, p);
    for (int k = 1; k <= pieces; ++k) declare_curve(piece_name(n, k), key_path(p, "pieces"));
  });
  each("curves",
       [&](const std::string& n, const Json&, const std::string& p) { declare_curve(n, p); });
  each("sketches", [&](const std::string& n, const Json& v, const std::string& p) {
    if (!v.is_object()) return;
    const auto e = v.find("entities");
    if (e == v.end() || !e->is_object()) return;
    for (const auto& [entity, ev] : e->items()) {
      (void)ev;
      const std::string ep = key_path(key_path(p, "entities"), entity);
      if (!valid_name(entity))
        c_.add(ep, "the name \"" + entity + "\" is not allowed; use 1 to 64 of A-Z a-z 0-9 _ -");
      declare_curve(n + "." + entity, ep);
    }
  });
  each("surfaces", [&](const std::string& n, const Json&, const std::string&) {
    names_.surfaces_declared.insert(n);
  });
  each("deformations",
       [&](const std::string& n, const Json&, const std::string&) { names_.stacks.push_back(n); });
  each("exports", [&](const std::string&, const Json&, const std::string&) {});
  each("models", [&](const std::string&, const Json&, const std::string&) {});  // file stems
}

std::optional<std::string> RecipeChecker::curve_ref(const Json& j, const std::string& path) {
  const auto name = c_.string(j, path);
  if (!name) return std::nullopt;
  if (Names::has(names_.curves, *name)) return name;
  if (names_.curves_declared.count(*name))
    c_.add(path, "the curve \"" + *name +
                     "\" is defined later in the recipe; a curve may only use "
                     "curves defined before it (move its definition up)");
  else
    c_.add(path, "no curve named \"" + *name + "\"; " + listing(names_.curves));
  return std::nullopt;
}

std::optional<std::string> RecipeChecker::surface_ref(const Json& j, const std::string& path) {
  const auto name = c_.string(j, path);
  if (!name) return std::nullopt;
  if (Names::has(names_.surfaces, *name)) return name;
  if (names_.surfaces_declared.count(*name))
    c_.add(path, "the surface \"" + *name +
                     "\" is defined later in \"surfaces\" (or is this one); "
                     "surfaces are built in document order: move its definition up");
  else
    c_.add(path, "no surface named \"" + *name + "\"; " + listing(names_.surfaces));
  return std::nullopt;
}

std::vector<std::string> RecipeChecker::curve_refs(const Json& obj, const std::string& path,
                                                   std::string_view key, std::size_t min,
                                                   std::size_t max) {
  const Json* j = c_.member(obj, path, key, true, "an array of curve names");
  if (!j) return {};
  const std::string p = key_path(path, key);
  if (!j->is_array() || j->size() < min || j->size() > max) {
    c_.add(p, "expected an array of " + std::to_string(min) +
                  (max > min ? " to " + std::to_string(max) : "") + " curve names, found " +
                  found(*j));
    return {};
  }
  std::vector<std::string> out;
  for (std::size_t i = 0; i < j->size(); ++i)
    if (const auto n = curve_ref((*j)[i], index_path(p, i))) out.push_back(*n);
  return out.size() == j->size() ? out : std::vector<std::string>{};
}

Composition RecipeChecker::composition(const Json& j, const std::string& path, Composition c) {
  // An old composition's "tolerance" was in mm where its "relative" was false.
  const bool old_mm = j.is_object() && j.contains("relative") && j.at("relative") == false;
  const Renamed renamed_tolerance =
      old_mm
          ? Renamed{"tolerance", "tolerance_mm", "in millimetres, as \"relative\": false made it"}
          : Renamed{"tolerance", "relative_tolerance", "a fraction of the size"};
  if (!c_.object(j, path,
                 {"mode", "relative_tolerance", "tolerance_mm", "degree", "check_samples",
                  "max_control_points", "accept_out_of_tolerance", "budget", "edges"},
                 "a composition {\"mode\": \"exact\"|\"refit\", ...}",
                 {renamed_tolerance, dropped_relative, renamed_editable}))
    return c;
  if (const Json* m = c_.member(j, path, "mode", false, ""))
    if (const auto k = c_.choice(*m, key_path(path, "mode"), {"exact", "refit"})) c.refit = *k == 1;
  // One tolerance, its unit in its key: a fraction of the size (the default) or millimetres.
  if (j.contains("tolerance_mm")) {
    c.tolerance_mm = c_.number_or(j, path, "tolerance_mm", 0.0, tolerance_range);
    c.relative_tolerance = 0;
    if (j.contains("relative_tolerance"))
      c_.add(key_path(path, "relative_tolerance"),
             "give one tolerance: \"relative_tolerance\" (a fraction of the size) or "
             "\"tolerance_mm\", not both");
  } else {
    c.relative_tolerance =
        c_.number_or(j, path, "relative_tolerance", c.relative_tolerance, tolerance_range);
  }
  c.degree = c_.integer_or(j, path, "degree", c.degree, 1, 25);
  c.check_samples = c_.integer_or(j, path, "check_samples", c.check_samples, 2, 64);
  c.accept_out_of_tolerance =
      c_.boolean_or(j, path, "accept_out_of_tolerance", c.accept_out_of_tolerance);
  // The refit's cap on its net (RefitOptions::max_control_points, 40,000 at most: the default,
  // which already takes about 20 s to reach), at least the (degree + 1)^2 of one patch.
  c.max_control_points =
      c_.integer_or(j, path, "max_control_points", c.max_control_points,
                    (c.degree + 1) * (c.degree + 1), limit::refit_control_points);
  // The budget (deform::Budget): within it exact, above it each step's certified light form at
  // `degree` and the tolerance, in at most max_control_points; "none": exact whatever the size.
  if (const Json* b = c_.member(j, path, "budget", false, "")) {
    const std::string bp = key_path(path, "budget");
    if (b->is_string() && *b == "none") {
      c.budget.reset();
    } else if (b->is_string()) {
      c_.add(bp,
             "expected \"none\" or a budget {\"max_degree\": 15, \"max_control_points\": "
             "10000}, found " +
                 found(*b));
    } else if (c_.object(*b, bp, {"max_degree", "max_control_points"},
                         "a budget {\"max_degree\": 15, \"max_control_points\": 10000} or "
                         "\"none\"")) {
      Budget budget = c.budget.value_or(Budget{});
      budget.max_degree = c_.integer_or(*b, bp, "max_degree", budget.max_degree, 1, 25);
      budget.max_control_points =
          c_.integer_or(*b, bp, "max_control_points", budget.max_control_points,
                        (c.degree + 1) * (c.degree + 1), limit::refit_control_points);
      if (c.degree > budget.max_degree)
        c_.add(key_path(bp, "max_degree"),
               "is " + std::to_string(budget.max_degree) + ", below the composition's \"degree\" " +
                   std::to_string(c.degree) +
                   " that light forms are fitted at; raise it or lower \"degree\"");
      c.budget = budget;
    }
  }
  // How closely a model's refitted faces follow their edges (deform::ModelDeformationOptions):
  // {"gap_mm", "angle_deg"} per face, or "alone" (each face fitted to its tolerance only).
  if (const Json* e = c_.member(j, path, "edges", false, "")) {
    const std::string ep = key_path(path, "edges");
    constexpr const char* shape =
        "{\"gap_mm\": 0.0005, \"angle_deg\": 0.008} (per face; two faces meet within twice "
        "these) or \"alone\"";
    if (e->is_string() && *e == "alone") {
      c.edge_gap_mm = c.edge_angle_deg = 0;
    } else if (e->is_string()) {
      c_.add(ep, std::string("expected ") + shape + ", found " + found(*e));
    } else if (c_.object(*e, ep, {"gap_mm", "angle_deg"}, shape)) {
      c.edge_gap_mm = c_.number_or(*e, ep, "gap_mm", 0.0005, {1e-9, 1e3});
      c.edge_angle_deg = c_.number_or(*e, ep, "angle_deg", 0.008, {1e-6, 10});
    }
  }
  return c;
}

void RecipeChecker::exporting(const std::string& name, const Json& j, const std::string& path) {
  if (!c_.object(j, path, {"surfaces", "formats", "schema", "profile"},
                 "an export {surfaces, formats, schema, profile}"))
    return;
  const std::size_t before = c_.problems.size();
  ExportDef def{name, path, {}, {"step", "iges", "glb"}, "AP214", "opencascade"};
  if (const Json* s = c_.member(j, path, "surfaces", true, "an array of surface names")) {
    const std::string sp = key_path(path, "surfaces");
    if (!s->is_array() || s->empty()) {
      c_.add(sp, "expected a non-empty array of surface names, found " + found(*s));
    } else if (c_.at_most(*s, sp, limit::entries, "surface names")) {
      // A surface listed twice would be written as two coincident faces; 100,000 times took a
      // minute and 4 GB (issue #18).
      std::map<std::string, std::size_t> first;
      for (std::size_t i = 0; i < s->size(); ++i) {
        const auto n = surface_ref((*s)[i], index_path(sp, i));
        if (!n) continue;
        if (const auto [it, fresh] = first.emplace(*n, i); !fresh)
          c_.add(index_path(sp, i), "the surface \"" + *n + "\" is already listed at [" +
                                        std::to_string(it->second) + "]; list each surface once");
        else
          def.surfaces.push_back(*n);
      }
    }
  }
  if (const Json* f = c_.member(j, path, "formats", false, ""))
    def.formats = formats(*f, key_path(path, "formats"));
  if (const Json* s = c_.member(j, path, "schema", false, ""))
    if (const auto k = c_.choice(*s, key_path(path, "schema"), {"AP214", "AP242"}))
      def.schema = *k == 0 ? "AP214" : "AP242";
  // The receiver profile (deform/receiver.hpp): what the receiving system takes.
  if (const Json* p = c_.member(j, path, "profile", false, "")) {
    std::vector<std::string> names;
    for (const auto& r : deform::receiver_profiles()) names.emplace_back(r.name);
    if (const auto k = c_.choice(*p, key_path(path, "profile"), names)) def.profile = names[*k];
  }
  if (c_.problems.size() == before) data.exports.push_back(std::move(def));
}

std::vector<std::string> RecipeChecker::formats(const Json& f, const std::string& fp) {
  std::vector<std::string> out;
  if (!f.is_array() || f.empty()) {
    c_.add(fp, "expected a non-empty array of \"step\", \"iges\", \"glb\", found " + found(f));
    return out;
  }
  for (std::size_t i = 0; i < f.size(); ++i)
    if (const auto k = c_.choice(f[i], index_path(fp, i), {"step", "iges", "glb"})) {
      const std::string fmt = f[i].get<std::string>();
      if (std::find(out.begin(), out.end(), fmt) != out.end())
        c_.add(index_path(fp, i), "\"" + fmt + "\" is listed twice; list each format once");
      else
        out.push_back(fmt);
    }
  return out;
}

std::optional<fs::path> RecipeChecker::exchange_file(const Json& f, const std::string& path) {
  const auto s = c_.string(f, path);
  if (!s) return std::nullopt;
  const fs::path file = fs::path(*s).is_absolute() ? fs::path(*s) : base_ / *s;
  std::string ext = file.extension().string();
  for (char& ch : ext) ch = static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
  if (ext != ".step" && ext != ".stp" && ext != ".igs" && ext != ".iges") {
    c_.add(path,
           "\"" + *s + "\" is not a STEP or IGES file; give a .step, .stp, .igs or .iges file");
    return std::nullopt;
  }
  if (std::error_code ec; !fs::is_regular_file(file, ec)) {
    // The error_code overload: the throwing one raised filesystem_error for a name the system
    // refuses (ENAMETOOLONG, found by fuzz_recipe), and checking never throws.
    c_.add(path,
           ec && ec != std::errc::no_such_file_or_directory
               ? "cannot look up \"" + file.string() + "\": " + ec.message() +
                     "; give the path of an existing file"
               : "no file \"" + file.string() + "\" (paths are relative to the recipe's folder)");
    return std::nullopt;
  }
  return file;
}

void RecipeChecker::modelling(const std::string& name, const Json& j, const std::string& path) {
  if (!c_.object(j, path,
                 {"import", "sew", "deformation", "bodies", "faces", "formats", "schema",
                  "allow_fold", "profile"},
                 "a model {import, deformation, bodies, faces, profile, formats, schema, sew}"))
    return;
  const std::size_t before = c_.problems.size();
  ModelDef def;
  def.name = name;
  def.path = path;
  for (const ExportDef& e : data.exports)
    if (e.name == name)
      c_.add(path, "the export \"" + name + "\" writes files of the same names (" + name +
                       ".step, ...); rename the model or the export");
  if (const Json* f =
          c_.member(j, path, "import", true, "the path of a .step/.stp/.igs/.iges file"))
    if (const auto file = exchange_file(*f, key_path(path, "import"))) def.file = *file;
  def.sew = c_.boolean_or(j, path, "sew", def.sew);
  def.allow_fold = c_.boolean_or(j, path, "allow_fold", def.allow_fold);
  if (const Json* d = c_.member(j, path, "deformation", false, "")) {
    const std::string dp = key_path(path, "deformation");
    if (const auto n = c_.string(*d, dp)) {
      const auto stack = std::find_if(data.stacks.begin(), data.stacks.end(),
                                      [&](const StackDef& s) { return s.name == *n; });
      if (stack == data.stacks.end()) {
        c_.add(dp, "no deformation stack named \"" + *n + "\"; " + listing(names_.stacks));
      } else {
        def.deformation = *n;
        // What a model cannot take: a style step (it shapes one surface by its control points)
        // and a direct move from a surface point (it needs one surface).
        for (const StepDef& step : stack->steps) {
          if (std::holds_alternative<StyleDef>(step.step))
            c_.add(dp, "the stack \"" + *n + "\" has a style step (" + step.path +
                           "), which shapes one surface by its control points; a model deforms "
                           "through lattices, direct manipulation and taper, twist, bend");
          if (const auto* direct = std::get_if<DirectDef>(&step.step))
            for (const DirectMove& m : direct->moves)
              if (m.on_surface) {
                c_.add(dp, "the stack \"" + *n + "\" moves a \"surface_point\" (" + step.path +
                               "), which needs one surface; give the move's \"point\" in space");
                break;
              }
        }
      }
    }
  }
  for (const auto& [key, out] :
       {std::pair{"bodies", &def.bodies}, std::pair{"faces", &def.faces}}) {
    const Json* list = c_.member(j, path, key, false, "");
    if (!list) continue;
    const std::string lp = key_path(path, key);
    if (!list->is_array() || list->empty()) {
      c_.add(lp,
             std::string("expected a non-empty array of ") + key + " names, found " + found(*list));
      continue;
    }
    if (!c_.at_most(*list, lp, limit::entries, "names")) continue;
    for (std::size_t i = 0; i < list->size(); ++i)
      if (const auto n = c_.string((*list)[i], index_path(lp, i))) out->push_back(*n);
  }
  if ((!def.bodies.empty() || !def.faces.empty()) && def.deformation.empty())
    c_.add(path,
           "\"bodies\" and \"faces\" choose what a deformation deforms; name one with "
           "\"deformation\"");
  // The receiver its deformed faces are written for (deform::ModelDeformationOptions::profile).
  if (const Json* p = c_.member(j, path, "profile", false, "")) {
    std::vector<std::string> names;
    for (const auto& r : deform::receiver_profiles()) names.emplace_back(r.name);
    if (const auto k = c_.choice(*p, key_path(path, "profile"), names)) def.profile = names[*k];
    if (def.deformation.empty())
      c_.add(key_path(path, "profile"),
             "a profile says how a deformed model's faces are written; a model without "
             "\"deformation\" is written as read: name a deformation or remove \"profile\"");
  }
  if (const Json* f = c_.member(j, path, "formats", false, ""))
    def.formats = formats(*f, key_path(path, "formats"));
  if (const Json* s = c_.member(j, path, "schema", false, ""))
    if (const auto k = c_.choice(*s, key_path(path, "schema"), {"AP214", "AP242"}))
      def.schema = *k == 0 ? "AP214" : "AP242";
  if (c_.problems.size() == before) data.models.push_back(std::move(def));
}

}  // namespace check_detail

using namespace check_detail;

namespace {

// ---- syntax: line and column, duplicate keys ----------------------------------------------------

std::pair<int, int> line_column(std::string_view text, std::size_t byte) {
  // nlohmann's byte is the 1-based position of the last character read: the end of the token
  // that broke the syntax. Report where that token starts (the start of "name" in a missing-comma
  // error), which is where the eye looks.
  std::size_t end = std::min(byte > 0 ? byte - 1 : 0, text.size());
  if (end < text.size() && text[end] == '"' && end > 0) {
    std::size_t k = end;
    while (k > 0 && !(text[k - 1] == '"' && (k < 2 || text[k - 2] != '\\'))) --k;
    if (k > 0) end = k - 1;
  } else {
    auto literal = [](char c) {
      return std::isalnum(static_cast<unsigned char>(c)) || c == '.' || c == '-' || c == '+';
    };
    while (end > 0 && end < text.size() && literal(text[end]) && literal(text[end - 1])) --end;
  }
  int line = 1;
  std::size_t line_start = 0;
  for (std::size_t i = 0; i < end; ++i)
    if (text[i] == '\n') ++line, line_start = i + 1;
  return {line, static_cast<int>(end - line_start) + 1};
}

/// Where arrays and objects first nest deeper than limit::depth (internal::nesting_too_deep),
/// named by the top-level key it is under and the bracket's line and column.
std::optional<Problem> too_deep(std::string_view text) {
  const auto deep = internal::nesting_too_deep(text, limit::depth);
  if (!deep) return std::nullopt;
  int line = 1;
  std::size_t line_start = 0;
  for (std::size_t i = 0; i < deep->at; ++i)
    if (text[i] == '\n') ++line, line_start = i + 1;
  return Problem{deep->top_key.empty() ? "(syntax)" : deep->top_key,
                 "arrays and objects nest deeper than " + std::to_string(limit::depth) +
                     " levels here (recipe limit; a recipe needs at most 8): remove the extra "
                     "brackets",
                 line, static_cast<int>(deep->at - line_start) + 1};
}

/// Parses with a callback that reports keys repeated in one object (nlohmann would keep the last
/// silently: a second curve of the same name would replace the first).
Json parse_reporting_duplicates(std::string_view text, Checker& c) {
  struct Level {
    bool array = false;
    long index = -1;
    std::string key;
    std::set<std::string> keys;
  };
  std::vector<Level> levels;
  auto path = [&] {
    std::string p;
    for (std::size_t i = 0; i + 1 < levels.size(); ++i)
      p = levels[i].array ? index_path(p, static_cast<std::size_t>(levels[i].index))
                          : key_path(p, levels[i].key);
    return p;
  };
  auto element = [&] {
    if (!levels.empty() && levels.back().array) ++levels.back().index;
  };
  Json::parser_callback_t cb = [&](int, Json::parse_event_t event, Json& parsed) {
    switch (event) {
      case Json::parse_event_t::object_start:
        element();
        levels.push_back({false, -1, "", {}});
        break;
      case Json::parse_event_t::array_start:
        element();
        levels.push_back({true, -1, "", {}});
        break;
      case Json::parse_event_t::object_end:
      case Json::parse_event_t::array_end:
        if (!levels.empty()) levels.pop_back();
        break;
      case Json::parse_event_t::key: {
        auto& top = levels.back();
        top.key = parsed.get<std::string>();
        if (!top.keys.insert(top.key).second) {
          levels.push_back({});  // so path() includes top's key
          c.add(path(), "the key \"" + top.key +
                            "\" appears twice in this object; only the last would "
                            "count: remove or rename one");
          levels.pop_back();
        }
        break;
      }
      case Json::parse_event_t::value:
        element();
        break;
    }
    return true;
  };
  const internal::FpTrapsHeld traps_held;  // the JSON parser's strtod
  try {
    return Json::parse(text.begin(), text.end(), cb);
  } catch (const Json::out_of_range& e) {  // a number beyond the double range: name where it is
    element();                             // the number being read is the next element
    levels.push_back({});                  // so path() includes the innermost level
    std::string what = e.what();
    if (const auto k = what.find("] "); k != std::string::npos) what = what.substr(k + 2);
    c.add(path(), what + "; give finite numbers within the range of a double");
    throw;
  }
}

}  // namespace

namespace {

/// Where a parsed document's arrays and objects first nest deeper than limit::depth, named by
/// the top-level key it is under (too_deep of the text, for a document held parsed).
std::optional<Problem> too_deep(const Json& root) {
  // Iterative, level by level from 2 (the root's values): a document built in code may nest
  // without bound.
  auto deeper = [](const Json& value) {
    std::vector<std::pair<const Json*, int>> open{{&value, 2}};
    while (!open.empty()) {
      const auto [node, level] = open.back();
      open.pop_back();
      if (!node->is_structured()) continue;
      if (level > limit::depth) return true;
      for (const Json& child : *node) open.emplace_back(&child, level + 1);
    }
    return false;
  };
  auto problem = [](const std::string& path) {
    return Problem{path,
                   "arrays and objects nest deeper than " + std::to_string(limit::depth) +
                       " levels here (recipe limit; a recipe needs at most 8): remove the extra "
                       "brackets",
                   0, 0};
  };
  if (root.is_object()) {
    for (const auto& [key, value] : root.items())
      if (deeper(value)) return problem(key);
  } else if (root.is_array()) {
    for (const Json& value : root)
      if (deeper(value)) return problem("(top level)");
  }
  return std::nullopt;
}

/// The schema's checks of a parsed document (whose syntax, duplicate keys and depth are checked).
CheckOutcome check_parsed(std::shared_ptr<const Json> root, const fs::path& base_dir, Checker& c) {
  CheckOutcome out;
  RecipeChecker rc(c, base_dir);
  rc.run(*root);
  out.data = std::move(rc.data);
  out.problems = recipe_problems(c);
  if (out.problems.empty())
    out.data.document =
        std::make_shared<const detail::DocumentJson>(detail::DocumentJson{std::move(root)});
  return out;
}

/// The problems as clay::Error(Document), one per line after `what` ("the recipe has 2
/// problems:").
[[noreturn]] void throw_problems(const std::string& what, const std::vector<Problem>& problems) {
  std::string m = what + "the recipe has " + std::to_string(problems.size()) + " problem" +
                  (problems.size() == 1 ? "" : "s") + ":";
  for (const auto& p : problems) m += "\n  " + to_string(p);
  throw Error(ErrorCategory::Document, m);
}

}  // namespace

CheckOutcome check(std::string_view text, const fs::path& base_dir) {
  Checker c;
  CheckOutcome out;
  if (text.size() > limit::text_bytes) {
    out.problems.push_back({"(top level)",
                            "the recipe is " + std::to_string(text.size()) + " bytes; at most " +
                                std::to_string(limit::text_bytes) +
                                " (64 MiB) are allowed (recipe limit)",
                            0, 0});
    return out;
  }
  if (auto deep = too_deep(text)) {
    out.problems.push_back(std::move(*deep));
    return out;
  }
  Json root;
  try {
    root = parse_reporting_duplicates(text, c);
  } catch (const Json::parse_error& e) {
    const auto [line, column] = line_column(text, e.byte);
    std::string what = e.what();
    // "[json.exception.parse_error.101] parse error at line 3, column 5: syntax error while
    // parsing object - unexpected ..." → keep the part after the position.
    if (const auto k = what.find(": syntax error"); k != std::string::npos)
      what = what.substr(k + 2);
    else if (const auto k2 = what.find("] "); k2 != std::string::npos)
      what = what.substr(k2 + 2);
    out.problems.push_back({"(syntax)",
                            what + "; fix the JSON syntax (NaN and Infinity are not JSON numbers)",
                            line, column});
    return out;
  } catch (const Json::exception& e) {  // a number beyond the range of a double
    std::string what = e.what();
    if (const auto k = what.find("] "); k != std::string::npos) what = what.substr(k + 2);
    out.problems = recipe_problems(c);  // where the number is (parse_reporting_duplicates)
    if (out.problems.empty())
      out.problems.push_back(
          {"(syntax)", what + "; give finite numbers within the range of a double", 0, 0});
    return out;
  }
  return check_parsed(std::make_shared<const Json>(std::move(root)), base_dir, c);
}

SketchDef rebuild_sketch(
    const SketchDef& def,
    const std::function<const surface::BSplineCurve*(const std::string&)>& curve) {
  Checker c;
  RecipeChecker rc(c, {});
  rc.runtime_curve = curve;
  std::vector<std::string> names;  // every name resolves through `curve`; unknown ones are reported
  const Json j = Json::parse(def.deferred_json);
  if (j.contains("entities") && j["entities"].is_object())
    for (const auto& [e, v] : j["entities"].items())
      if (v.is_object() && v.contains("curve") && v["curve"].is_string()) {
        const std::string n = v["curve"].get<std::string>();
        if (curve(n)) names.push_back(n);
      }
  rc.know_curves(std::move(names));
  rc.rebuild(def.name, j, def.path);
  if (!c.problems.empty()) {
    std::string m = "with the run's curves the sketch has " + std::to_string(c.problems.size()) +
                    " problem" + (c.problems.size() == 1 ? "" : "s") + ":";
    for (const auto& p : recipe_problems(c)) m += "\n  " + to_string(p);
    throw Error(ErrorCategory::InvalidGeometry, m);
  }
  return std::move(rc.data.sketches.front());
}

namespace {

// Hand-written scans, not std::regex: libstdc++'s regex matcher recurses once per character, so
// a message quoting a 30,000-character recipe key overflowed the stack (found by fuzz_recipe).

bool word_start(const std::string& m, std::size_t at) {
  return at == 0 || !(std::isalnum(static_cast<unsigned char>(m[at - 1])) || m[at - 1] == '_');
}

/// The number written between `before` and `after` ("control point limit 40000 reached"), or -1.
long number_between(const std::string& m, std::string_view before, std::string_view after) {
  for (std::size_t at = m.find(before); at != std::string::npos; at = m.find(before, at + 1)) {
    std::size_t end = at + before.size();
    while (end < m.size() && std::isdigit(static_cast<unsigned char>(m[end]))) ++end;
    const std::size_t digits = end - at - before.size();
    if (digits > 0 && digits < 10 && m.compare(end, after.size(), after) == 0)
      return std::stol(m.substr(at + before.size(), digits));
  }
  return -1;
}

/// Removes every "XxxOptions::" (a capitalized word ending in Options, at a word start).
std::string without_options_structs(const std::string& m) {
  static constexpr std::string_view tail = "Options::";
  std::string out;
  std::size_t copied = 0;
  for (std::size_t at = m.find(tail); at != std::string::npos; at = m.find(tail, at + 1)) {
    std::size_t start = at;
    while (start > copied && std::isalpha(static_cast<unsigned char>(m[start - 1]))) --start;
    if (start == at || !std::isupper(static_cast<unsigned char>(m[start])) || !word_start(m, start))
      continue;
    out.append(m, copied, start - copied);
    copied = at + tail.size();
  }
  return out.append(m, copied, std::string::npos);
}

/// Removes "deform_surface: steps[N] (...)" (with a following ": "), "compose_exact: " and
/// "refit_deformed: " where they start a word.
std::string without_library_prefixes(const std::string& m) {
  std::string out;
  std::size_t at = 0;
  while (at < m.size()) {
    if (word_start(m, at)) {
      std::size_t end = std::string::npos;
      if (m.compare(at, 13, "compose_exact") == 0 && m.compare(at + 13, 2, ": ") == 0) {
        end = at + 15;
      } else if (m.compare(at, 14, "refit_deformed") == 0 && m.compare(at + 14, 2, ": ") == 0) {
        end = at + 16;
      } else if (m.compare(at, 22, "deform_surface: steps[") == 0) {
        std::size_t k = at + 22;
        while (k < m.size() && std::isdigit(static_cast<unsigned char>(m[k]))) ++k;
        if (k > at + 22 && m.compare(k, 3, "] (") == 0) {
          const std::size_t close = m.find(')', k + 3);
          if (close != std::string::npos) {
            end = close + 1;
            if (m.compare(end, 2, ": ") == 0) end += 2;
          }
        }
      }
      if (end != std::string::npos) {
        at = end;
        continue;
      }
    }
    out += m[at++];
  }
  return out;
}

}  // namespace

std::string recipe_wording(std::string m) {
  // The library's fixes, as a recipe applies them (or dropped where a recipe cannot).
  static const std::pair<std::string_view, std::string_view> phrases[] = {
      {"Allow a certified refit (SurfaceDeformationOptions::refit) to approximate this step within "
       "a tolerance",
       "Allow a certified refit to approximate this step within a tolerance: give the deformation "
       "\"composition\": {\"mode\": \"refit\", \"relative_tolerance\": 1e-4} (a fraction of the "
       "size)"},
      {"set SurfaceDeformationOptions::accept_out_of_tolerance",
       "set \"accept_out_of_tolerance\": true in the \"composition\""},
      {"(RefitOptions::tolerance_mm, relative_tolerance = 0)",
       "(\"tolerance_mm\" in the \"composition\")"},
      {"remove the repeated point or set FitOptions::drop_duplicates", "remove the repeated point"},
      {" (or build the plane with make_plane)", ""},
      {"; build the plane with make_plane(origin, normal, x direction)",
       "; give a \"y_axis\" perpendicular to the \"x_axis\""},
      {"reverse it or set LoftOptions::auto_orient", "reverse it (a curve {\"reversed\": NAME})"},
      {"loosen SuperquadricOptions::tolerance_mm, raise max_spans, ", "loosen \"tolerance_mm\" "},
      {"not reached at max_sections", "not reached with the most sections allowed"},
      {"raise gap_tolerance", "raise \"gap_tolerance\""},
  };
  // A refit's advice depends on the limit it hit: a recipe can raise max_control_points (up to
  // its 40,000 cap), not the iteration or per-direction limits.
  if (const auto at = m.find("; raise the limits, the tolerance or the degree");
      at != std::string::npos) {
    const long reached = number_between(m, "control point limit ", " reached");
    const bool raisable = reached >= 0 && reached < limit::refit_control_points;
    m.replace(at, std::string_view("; raise the limits, the tolerance or the degree").size(),
              raisable
                  ? "; raise the composition's \"max_control_points\" (at most 40,000), loosen its "
                    "tolerance (\"relative_tolerance\" or \"tolerance_mm\") or raise its \"degree\""
                  : "; loosen the composition's tolerance (\"relative_tolerance\" or "
                    "\"tolerance_mm\") or "
                    "raise its \"degree\", or deform less");
  }
  for (const auto& [from, to] : phrases)
    for (std::size_t at = m.find(from); at != std::string::npos; at = m.find(from, at + to.size()))
      m.replace(at, from.size(), to);
  // What is left: a field of a C++ options struct in a validation message ("SweepOptions::
  // twist_degrees is ..."), which for the options a recipe sets is the recipe's own key.
  m = without_options_structs(m);
  // The library's own prefixes: the recipe path in front of the message already names the step
  // (and a recipe runs deform_surface one step at a time, so its "steps[0]" would mislead).
  return without_library_prefixes(m);
}

std::string to_string(const Problem& problem) {
  std::string s;
  if (problem.line > 0)
    s = "line " + std::to_string(problem.line) + ", column " + std::to_string(problem.column) +
        ": ";
  if (problem.path != "(syntax)") s += problem.path + ": ";
  return s + problem.message;
}

std::vector<Problem> check_recipe(std::string_view text, const fs::path& base_dir) {
  return check(text, base_dir).problems;
}

Recipe parse_recipe(std::string_view text, const fs::path& base_dir,
                    std::string_view default_name) {
  CheckOutcome out = check(text, base_dir);
  if (!out.problems.empty()) throw_problems("", out.problems);
  if (out.data.name.empty()) out.data.name = std::string(default_name);
  return Recipe{std::make_shared<const RecipeData>(std::move(out.data))};
}

Recipe parse_recipe_document(std::shared_ptr<const nlohmann::ordered_json> document,
                             const fs::path& base_dir, std::string_view default_name) {
  if (!document)
    throw Error(ErrorCategory::InvalidArgument,
                "parse_recipe_document: the document is null; pass a parsed recipe");
  if (auto deep = too_deep(*document)) throw_problems("", {*deep});
  Checker c;
  CheckOutcome out = check_parsed(std::move(document), base_dir, c);
  if (!out.problems.empty()) throw_problems("", out.problems);
  if (out.data.name.empty()) out.data.name = std::string(default_name);
  return Recipe{std::make_shared<const RecipeData>(std::move(out.data))};
}

Recipe load_recipe(const fs::path& file) {
  CheckOutcome out = check(internal::read_text(file, "recipe"), file.parent_path());
  if (!out.problems.empty()) throw_problems(file.string() + ": ", out.problems);
  if (out.data.name.empty()) out.data.name = file.stem().string();
  return Recipe{std::make_shared<const RecipeData>(std::move(out.data))};
}

const std::string& Recipe::name() const {
  static const std::string empty;
  return data ? data->name : empty;
}

std::vector<std::string> Recipe::deformation_names() const {
  std::vector<std::string> out;
  if (data)
    for (const auto& s : data->stacks) out.push_back(s.name);
  return out;
}

}  // namespace clay::recipe
