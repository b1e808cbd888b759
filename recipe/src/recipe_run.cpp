// Running a checked recipe in memory: every step in order, each timed and reported with the
// quality figures of DESIGN.md; a failing step is rethrown with its path first.
#include "recipe_run.hpp"
#include "run_cache.hpp"

#include <clay/brep/volume.hpp>
#include <clay/cancel.hpp>
#include <clay/constraints/solve.hpp>
#include <clay/deform/jacobian.hpp>
#include <clay/deform/model_deformation.hpp>
#include <clay/deform/receiver.hpp>
#include <clay/deform/surface_deformation.hpp>
#include <clay/error.hpp>
#include <clay/occt/model_exchange.hpp>
#include <clay/occt/surface_exchange.hpp>
#include <clay/sketch/entities.hpp>
#include <clay/surface/evaluate.hpp>

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <functional>
#include <map>
#include <optional>
#include <set>

namespace clay::recipe {

namespace {

namespace fs = std::filesystem;
using surface::BSplineCurve;
using surface::BSplineSurface;
using namespace detail;

/// The run's state: named results so far, and the reports.

class Runner {
 public:
  Runner(const RecipeData& d, const RunOptions& o, RunResult& r)
      : data_(d), options_(o), result_(r) {}

  /// Strokes, curves and sketches: every named curve, each after what it needs (a curve taken
  /// from a surface after that surface and the curves it is built from).
  void curves() {
    for (const auto& s : data_.strokes) need_curve(s.pieces == 0 ? s.name : piece_name(s.name, 1));
    for (const auto& c : data_.curves) need_curve(c.name);
    for (std::size_t k = 0; k < data_.sketches.size(); ++k) need_sketch(k);
  }
  /// Every named surface, in document order unless one needs another first.
  void surfaces() {
    for (const auto& s : data_.surfaces) need_surface(s.name);
  }

  /// Above the default budget an exported surface gets a warning: few surfacing tools edit more.
  static constexpr Budget default_budget{};

  /// Every export, its surfaces made to conform to its receiver profile (deform/receiver.hpp):
  /// as they are when they conform, else refitted (certified) at the profile's degree within the
  /// recipe composition's tolerance; the exact profile writes each surface's exact reference.
  void exports() {
    for (const auto& e : data_.exports)
      timed(e.path, "export", [&](StepReport& rep) {
        ExportResult x;
        x.name = e.name;
        x.surface_names = e.surfaces;
        x.formats = e.formats;
        x.schema = e.schema;
        x.profile = options_.profile.empty() ? e.profile : options_.profile;
        conform(x, rep);
        result_.exports.push_back(std::move(x));
      });
    result_.bounds.assign(bound_of_.begin(), bound_of_.end());
  }

  /// Seeds the ledger from an earlier run's (conform_export).
  void seed_bounds(const std::vector<std::pair<std::string, double>>& bounds) {
    bound_of_.insert(bounds.begin(), bounds.end());
  }

  /// Fills x.surfaces from x.surface_names made to conform to x.profile, x.bounds_mm with their
  /// bounds, and the export step's figures and message.
  void conform(ExportResult& x, StepReport& rep) const {
    const deform::ReceiverProfile& profile = deform::receiver_profile(x.profile);
    // A preview alone (glb) takes any degree: written as it is.
    const bool preview_only =
        !x.formats.empty() &&
        std::all_of(x.formats.begin(), x.formats.end(), [](const auto& f) { return f == "glb"; });
    x.surfaces.clear();
    x.bounds_mm.clear();
    long points = 0;
    int degree = 0, refitted = 0;
    double worst = 0;
    for (const auto& n : x.surface_names) {
      throw_if_cancelled("an export's receiver fits");
      double bound = bound_of(n);
      BSplineSurface s =
          profile.fit_degree == 0 && bound > 0 ? exact_reference(n, bound) : surface_of(n);
      if (!preview_only) {
        const deform::ProfileFit f =
            deform::fit_to_profile(s, profile, light_fit(data_.composition), "surface '" + n + "'");
        bound += f.bound_mm;
        refitted += f.refitted ? 1 : 0;
        s = f.surface;
      }
      x.surfaces.push_back(std::move(s));
      x.bounds_mm.push_back(bound);
      worst = std::max(worst, bound);
      points += x.surfaces.back().points.rows();
      degree = std::max({degree, x.surfaces.back().u.degree, x.surfaces.back().v.degree});
    }
    rep.figures = {{"patches", static_cast<long long>(x.surfaces.size())},
                   {"control_points", static_cast<long long>(points)},
                   {"degree", static_cast<long long>(degree)},
                   {"profile", x.profile},
                   {"surfaces_refitted", static_cast<long long>(refitted)}};
    if (std::isfinite(worst))
      rep.figures.emplace_back("max_deviation_mm", worst);
    else
      rep.figures.emplace_back("deviation", std::string("unbounded"));
    rep.message = std::to_string(x.surfaces.size()) + " surface(s) for " + x.name + " (profile " +
                  x.profile + (refitted > 0 ? ", " + std::to_string(refitted) + " refitted" : "") +
                  (worst > 0 ? ", within " + format("%.3g", worst) + " mm of the exact" : "") + ")";
    // Exact results can be far beyond what surfacing tools edit: say so, per surface.
    for (std::size_t k = 0; k < x.surfaces.size(); ++k) {
      const BSplineSurface& f = x.surfaces[k];
      const std::optional<Budget> own = budget_of(x.surface_names[k]);
      auto within = [&](const Budget& b) {
        return std::max(f.u.degree, f.v.degree) <= b.max_degree &&
               f.points.rows() <= b.max_control_points;
      };
      // Within the default budget, or within a budget its recipe chose: no warning.
      if (within(default_budget) || (own && within(*own))) continue;
      rep.warning = true;
      rep.message +=
          "; surface '" + x.surface_names[k] + "' has degree " + std::to_string(f.u.degree) +
          " x " + std::to_string(f.v.degree) + " and " + std::to_string(f.points.rows()) +
          " control points, more than most surfacing tools edit (the default budget: degree " +
          std::to_string(default_budget.max_degree) + ", " +
          std::to_string(default_budget.max_control_points) + " control points): " +
          (own ? std::string("export it for a lighter receiver (\"profile\": \"bicubic\" or "
                             "\"class_a\") or rebuild it lighter")
               : std::string("give its composition a \"budget\" (not \"none\") to export a "
                             "certified light form"));
    }
  }

  /// Every imported model, deformed when it names a stack.
  void models() {
    for (const auto& m : data_.models)
      timed(m.path, "model", [&](StepReport& rep) {
        result_.models.push_back(run_model(data_, m, options_.profile));
        const ModelRunResult& r = result_.models.back();
        const deform::ModelDeformationReport& x = r.report;
        rep.figures = {{"faces", static_cast<long long>(x.counts.faces)},
                       {"faces_exact", static_cast<long long>(x.faces_exact)},
                       {"faces_refit", static_cast<long long>(x.faces_refit)},
                       {"faces_untouched", static_cast<long long>(x.faces_untouched)},
                       {"max_certified_bound_mm", x.max_certified_bound_mm},
                       {"max_edge_gap_mm", x.max_edge_gap_mm},
                       {"volume_before_mm3", x.volume_before_mm3},
                       {"volume_after_mm3", x.volume_after_mm3},
                       {"fold_free", r.fold_free}};
        rep.message =
            (r.deformation.empty() ? "read as it is: " : "deformed by " + r.deformation + ": ") +
            x.brief();
      });
  }

  /// One named surface deformed by a stack (the deform command and `deform` surfaces), starting
  /// the bound ledger at `input_bound` (how far `parent` may be from its exact reference). Steps
  /// above the composition's budget yield their light form; a final surface (nothing is built on
  /// it) still above the budget (a style result) leaves as a certified light copy.
  ///
  /// With `prefix_key` (k -> the key of the stack's first k steps on this surface, or none), the
  /// steps before the last are kept in the run's cache one by one as they are made, and a run
  /// takes from it the longest first steps it holds: a sweep or an edit of a later step (a
  /// lattice after a style) does not style again. The last step is kept with the whole surface.
  BSplineSurface deform(
      const BSplineSurface& parent, const StackDef& stack, const Composition& c,
      const std::string& path, const std::string& name, bool final_surface = true,
      double input_bound = 0,
      const std::function<std::optional<std::string>(std::size_t)>& prefix_key = {}) {
    BSplineSurface s = parent;
    ledger_ = input_bound;
    std::size_t first = 0;  // the first step to run: those before it are taken from the cache
    const bool keeping = options_.cache && prefix_key && stack.steps.size() > 1;
    if (keeping)
      for (; first + 1 < stack.steps.size(); ++first) {
        const std::optional<std::string> key = prefix_key(first + 1);
        const auto hit = key ? CacheAccess::find(*options_.cache, "stage\n" + *key) : nullptr;
        if (!hit) break;
        s = hit->surfaces.front().second;
        ledger_ = hit->bounds.front().second;
        for (StepReport rep : hit->steps) {
          rep.reused = true;
          if (options_.progress) options_.progress(rep);
          result_.steps.push_back(std::move(rep));
        }
        result_.stages.insert(result_.stages.end(), hit->stages.begin(), hit->stages.end());
      }
    for (std::size_t i = first; i < stack.steps.size(); ++i) {
      const StepDef& step = stack.steps[i];
      const std::string p = path + ".steps[" + std::to_string(i) + "]";
      const std::size_t steps0 = result_.steps.size(), stages0 = result_.stages.size();
      timed(p, step.kind, [&](StepReport& rep) {
        rep.message = step.path + (step.name.empty() ? "" : " '" + step.name + "'");
        if (!step.enabled) {
          rep.message += ": disabled, skipped";
          return;
        }
        if (!step.keep.empty())
          throw Error(ErrorCategory::InvalidArgument,
                      "\"keep\" holds a solid's volume or centroid while its lattice moves, "
                      "but this stack deforms the surface \"" +
                          name +
                          "\"; use it in a stack that deforms a model (\"models\"), or "
                          "remove it");
        Stage stage{name, p, step.kind, s, {}, {}, {}, {}};
        if (const auto* style = std::get_if<StyleDef>(&step.step)) {
          if (!style->bound.empty()) stage.curves.push_back(style->bound);
          stage.curves.push_back(style->target);
        }
        s = std::visit([&](const auto& d) { return apply(d, s, c, rep, stage); }, step.step);
        stage.after = s;
        result_.stages.push_back(std::move(stage));
      });
      // Kept: this step's report, stage, surface and ledger after it, under its prefix's key
      // (not the last step's: the whole surface's entry holds it; never a drag's preview).
      if (keeping && i + 1 < stack.steps.size() && !previewing_)
        if (const std::optional<std::string> key = prefix_key(i + 1)) {
          CacheEntry e;
          e.surfaces.emplace_back(name, s);
          e.bounds.emplace_back(name, ledger_);
          e.steps.assign(result_.steps.begin() + static_cast<std::ptrdiff_t>(steps0),
                         result_.steps.end());
          e.stages.assign(result_.stages.begin() + static_cast<std::ptrdiff_t>(stages0),
                          result_.stages.end());
          CacheAccess::keep(*options_.cache, "stage\n" + *key, std::move(e));
        }
    }
    if (c.budget && final_surface &&
        (std::max(s.u.degree, s.v.degree) > c.budget->max_degree ||
         s.points.rows() > c.budget->max_control_points))
      timed(path + ".composition.budget", "light",
            [&](StepReport& rep) { s = light_copy(s, c, name, rep); });
    bound_of_[name] = ledger_;
    if (previewing_) result_.previewed.push_back(name);
    previewing_ = false;
    return s;
  }

  /// The certified light copy of a final surface above the budget: refitted at the composition's
  /// degree within its tolerance, from the surface's rough breakpoints only
  /// (deform::refit_surface), into at most the composition's max_control_points.
  BSplineSurface light_copy(const BSplineSurface& s, const Composition& c, const std::string& name,
                            StepReport& rep) {
    deform::RefitOptions fit = light_fit(c);
    follow_shared(fit, shared(), c);
    const deform::RefitResult r = deform::refit_surface(s, fit);
    const auto& f = r.report;
    rep.figures = {{"exact_degree_u", static_cast<long long>(s.u.degree)},
                   {"exact_degree_v", static_cast<long long>(s.v.degree)},
                   {"exact_control_points", static_cast<long long>(s.points.rows())},
                   {"degree_u", static_cast<long long>(r.surface.u.degree)},
                   {"degree_v", static_cast<long long>(r.surface.v.degree)},
                   {"control_points", static_cast<long long>(r.surface.points.rows())},
                   {"certified", f.certified},
                   {"max_deviation_mm", f.certified ? f.certified_bound_mm : f.sampled_max},
                   {"sampled_max_mm", f.sampled_max},
                   {"tolerance_mm", f.tolerance_mm},
                   {"size", f.size}};
    rep.message = "surface '" + name + "' above the budget (degree " +
                  std::to_string(c.budget->max_degree) + ", " +
                  std::to_string(c.budget->max_control_points) +
                  " control points) leaves as its light form: degree " +
                  std::to_string(s.u.degree) + " x " + std::to_string(s.v.degree) + ", " +
                  std::to_string(s.points.rows()) + " control points -> degree " +
                  std::to_string(r.surface.u.degree) + " x " + std::to_string(r.surface.v.degree) +
                  ", " + std::to_string(r.surface.points.rows()) + " control points, " + f.brief();
    ledger(rep, f.certified ? f.certified_bound_mm : std::numeric_limits<double>::infinity());
    // A light copy that misses its tolerance is a failure, unless the composition accepts
    // refits out of tolerance: then it carries a warning, as a refitted step does.
    if (!f.summary.converged()) {
      if (!c.accept_out_of_tolerance)
        throw Error(ErrorCategory::ToleranceNotMet,
                    "the light form of surface '" + name +
                        "' misses its tolerance: " + f.summary.message +
                        "; raise the composition's \"max_control_points\" or its tolerance "
                        "(\"relative_tolerance\" or \"tolerance_mm\"), or raise \"budget\" "
                        "(or set it to \"none\") to keep the exact surface");
      rep.warning = true;
      rep.message += "; accepted out of tolerance (\"accept_out_of_tolerance\": true)";
    }
    return r.surface;
  }

  /// The ledger after a step: `bound` (mm) added to it, and its figure on the step.
  void ledger(StepReport& rep, double bound) {
    ledger_ = ledger_ + bound;
    ledger_figure(rep);
  }
  void ledger_figure(StepReport& rep) const {
    if (std::isfinite(ledger_))
      rep.figures.emplace_back("accumulated_bound_mm", ledger_);
    else
      rep.figures.emplace_back("accumulated_bound", std::string("unbounded"));
  }
  /// The named surface recomputed with every composition exact (no budget): the exact profile's
  /// reference, computed only when asked for. `bound` becomes its own ledger (what rebuilds in
  /// its chain still carry).
  BSplineSurface exact_reference(const std::string& name, double& bound) const {
    RecipeData exact = data_;
    exact.composition.budget.reset();
    for (SurfaceDef& def : exact.surfaces)
      if (auto* d = std::get_if<DeformDef>(&def.build)) d->composition.budget.reset();
    RunResult scratch;
    const RunOptions quiet;
    Runner runner(exact, quiet, scratch);
    runner.need_surface(name);
    bound = runner.bound_of(name);
    return scratch.surface(name);
  }

  /// The budget that applied to the named surface: its deform's composition's, else the
  /// recipe's (empty: "none").
  std::optional<Budget> budget_of(const std::string& name) const {
    for (const SurfaceDef& def : data_.surfaces)
      if (const auto* d = std::get_if<DeformDef>(&def.build); d && def.name == name)
        return d->composition.budget;
    return data_.composition.budget;
  }

  /// How far the named surface may be from its exact reference (mm; 0 when exact).
  double bound_of(const std::string& name) const {
    const auto it = bound_of_.find(name);
    return it == bound_of_.end() ? 0.0 : it->second;
  }

  const BSplineSurface& surface_of(const std::string& name) const {
    for (const auto& [n, s] : result_.surfaces)
      if (n == name) return s;
    throw Error(ErrorCategory::Internal,
                "recipe run: surface '" + name + "' missing after checking");
  }
  const BSplineCurve& curve_of(const std::string& name) const {
    const auto it = curve_index_.find(name);
    if (it == curve_index_.end())
      throw Error(ErrorCategory::Internal,
                  "recipe run: curve '" + name + "' missing after checking");
    return result_.curves[it->second].second;
  }

 private:
  const RecipeData& data_;
  const RunOptions& options_;
  RunResult& result_;
  std::map<std::string, std::size_t> curve_index_;
  std::set<std::size_t> sketches_built_;  // indices into data_.sketches
  // The digests of the keys of the steps that gave each curve and surface (RunOptions::cache).
  Digests digests_;
  std::set<std::string> building_;  // "curve NAME" / "surface NAME" being built
  // The bound ledger (issue #38): how far each surface, and the one being deformed, may be from
  // its exact reference, the recipe with every step exact (mm; inf: not bounded).
  std::map<std::string, double> bound_of_;
  double ledger_ = 0;
  std::map<std::string, bool> affected_;  // by surface name: needs what changed
  bool previewing_ = false;               // the surface being deformed has a previewed step
  // The sides the surface being deformed shares with others, which its fits follow (issue #38
  // step 3), found when a step first composes: a studio drag's preview never pays for them.
  const BSplineSurface* shared_parent_ = nullptr;
  const Composition* shared_composition_ = nullptr;
  std::optional<std::vector<deform::MatchedCurve>> shared_;
  const std::vector<deform::MatchedCurve>& shared() {
    if (!shared_)
      shared_ = shared_parent_
                    ? shared_sides(*shared_parent_, result_.surfaces, *shared_composition_)
                    : std::vector<deform::MatchedCurve>{};
    return *shared_;
  }

  template <class F>
  void timed(const std::string& path, const std::string& kind, F&& f) {
    StepReport rep;
    rep.path = path;
    rep.kind = kind;
    const auto t0 = Clock::now();
    // A cancel (clay/cancel.hpp) stops a run between steps as well as inside the long ones.
    throw_if_cancelled("a recipe's steps");
    if (options_.starting) options_.starting(path, kind);
    try {
      f(rep);
    } catch (const Error& e) {
      throw Error(e.category(), path + " (" + kind + "): " + recipe_wording(e.message()));
    }
    rep.seconds = seconds_since(t0);
    if (options_.progress) options_.progress(rep);
    result_.steps.push_back(std::move(rep));
  }

  /// Builds the curve `name` unless built: first what it needs, then its stroke, curve or sketch
  /// (each taken from the run's cache when its key is there).
  void need_curve(const std::string& name) {
    if (curve_index_.count(name)) return;
    guard("curve " + name, [&] {
      const Needs needs = curve_needs(data_, name);
      for (const auto& c : needs.curves) need_curve(c);
      for (const auto& s : needs.surfaces) need_surface(s);
      for (const auto& s : data_.strokes)
        if (defines(s, name))
          return cached([&] { return own_key(data_, digests_, "strokes", s.name, needs); },
                        [&] { timed(s.path, "stroke", [&](StepReport& rep) { stroke(s, rep); }); });
      for (const auto& c : data_.curves)
        if (c.name == name)
          return cached([&] { return own_key(data_, digests_, "curves", c.name, needs); },
                        [&] { timed(c.path, c.kind, [&](StepReport& rep) { curve(c, rep); }); });
      for (std::size_t k = 0; k < data_.sketches.size(); ++k)
        for (const auto& [entity, id] : data_.sketches[k].entities)
          if (entity == name) return need_sketch(k);
    });
  }
  void need_sketch(std::size_t k) {
    if (sketches_built_.count(k)) return;
    sketches_built_.insert(k);
    const SketchDef& s = data_.sketches[k];
    for (const auto& c : s.uses) need_curve(c);
    cached(
        [&] {
          return own_key(data_, digests_, "sketches", s.name, Needs{s.uses, {}});
        },
        [&] { timed(s.path, "sketch", [&](StepReport& rep) { sketch(s, rep); }); });
  }
  void need_surface(const std::string& name) {
    if (std::any_of(result_.surfaces.begin(), result_.surfaces.end(),
                    [&](const auto& s) { return s.first == name; }))
      return;
    guard("surface " + name, [&] {
      for (const SurfaceDef& def : data_.surfaces)
        if (def.name == name) {
          const Needs needs = surface_needs(data_, def);
          for (const auto& c : needs.curves) need_curve(c);
          for (const auto& s : needs.surfaces) need_surface(s);
          return cached(
              [&] { return surface_key(data_, digests_, def, needs, result_.surfaces); },
              [&] {
                // Taken from the previous run when nothing it needs changed (run_reuse.cpp).
                if (options_.previous && options_.take_from_previous &&
                    !needs_changed(data_, *options_.previous, options_.changed_deformations, name,
                                   affected_) &&
                    take_surface(*options_.previous, def, result_, bound_of_, options_.progress))
                  return;
                build_surface(def);
              });
        }
    });
  }

  // ---- what earlier runs give (RunOptions::cache; run_cache.hpp) -----------------------------

  /// Runs `build` (one step: a stroke, a curve, a sketch, or a surface with its stack), or takes
  /// what it adds from the run's cache when its key is there; what it adds is kept under the
  /// key. Every curve and surface it adds gets a digest of the key, which the keys of the steps
  /// built on it contain. Without a cache (or a document to key on) it only builds.
  template <class K, class B>
  void cached(K&& key_of, B&& build) {
    if (!options_.cache || !data_.document) return build();
    const std::optional<std::string> key = key_of();
    if (!key) return build();
    const std::string d = digest(*key);
    if (const auto hit = CacheAccess::find(*options_.cache, *key)) return take(*hit, d);
    const std::size_t curves0 = result_.curves.size(), surfaces0 = result_.surfaces.size(),
                      steps0 = result_.steps.size(), stages0 = result_.stages.size(),
                      previewed0 = result_.previewed.size();
    build();
    CacheEntry e;
    e.curves.assign(result_.curves.begin() + static_cast<std::ptrdiff_t>(curves0),
                    result_.curves.end());
    e.surfaces.assign(result_.surfaces.begin() + static_cast<std::ptrdiff_t>(surfaces0),
                      result_.surfaces.end());
    e.steps.assign(result_.steps.begin() + static_cast<std::ptrdiff_t>(steps0),
                   result_.steps.end());
    e.stages.assign(result_.stages.begin() + static_cast<std::ptrdiff_t>(stages0),
                    result_.stages.end());
    for (const auto& [n, s] : e.surfaces)
      if (const auto b = bound_of_.find(n); b != bound_of_.end())
        e.bounds.emplace_back(n, b->second);
    note_digests(digests_, e, d);
    // A drag's preview is uncertified: never kept.
    if (result_.previewed.size() == previewed0)
      CacheAccess::keep(*options_.cache, *key, std::move(e));
  }

  /// Adds a kept entry to the run as building it would have, its reports marked reused.
  void take(const CacheEntry& e, const std::string& d) {
    for (const auto& [n, c] : e.curves) add_curve(n, c);
    for (const auto& s : e.surfaces) result_.surfaces.push_back(s);
    for (StepReport rep : e.steps) {
      rep.reused = true;
      if (options_.progress) options_.progress(rep);
      result_.steps.push_back(std::move(rep));
    }
    result_.stages.insert(result_.stages.end(), e.stages.begin(), e.stages.end());
    for (const auto& [n, b] : e.bounds) bound_of_[n] = b;
    note_digests(digests_, e, d);
  }

  // ---- what an earlier run gives (RunOptions::previous) ---------------------------------------

  /// Runs f for `node` once at a time: the checker reports cycles, so meeting one here is a bug.
  template <class F>
  void guard(const std::string& node, F&& f) {
    if (!building_.insert(node).second)
      throw Error(ErrorCategory::Internal,
                  "recipe run: " + node + " needs itself (please report this recipe)");
    f();
    building_.erase(node);
  }

  void add_curve(const std::string& name, BSplineCurve c) {
    curve_index_[name] = result_.curves.size();
    result_.curves.emplace_back(name, std::move(c));
  }

  /// Whether the stroke's fit gives the curve `name`: its own name, or one of its pieces.
  static bool defines(const StrokeDef& s, const std::string& name) {
    if (s.pieces == 0) return s.name == name;
    for (int k = 1; k <= s.pieces; ++k)
      if (piece_name(s.name, k) == name) return true;
    return false;
  }

  void stroke(const StrokeDef& s, StepReport& rep) {
    for (auto& [name, c] : stroke_curves(s, rep, options_.cache.get()))
      add_curve(name, std::move(c));
  }

  void curve(const CurveDef& c, StepReport& rep) {
    std::optional<surface::FittedCurve> fitted;
    BSplineCurve out;
    if (c.curve) {
      out = *c.curve;
    } else if (!c.mirror_of.empty()) {
      out = surface::mirrored(curve_of(c.mirror_of), c.plane.origin, c.plane.normal);
    } else if (!c.reversed_of.empty()) {
      out = surface::reversed(curve_of(c.reversed_of));
    } else if (c.kind == "iso" || c.kind == "boundary") {
      const BSplineSurface& s = surface_of(c.surface);
      const auto [a, b] = c.fixed_u ? s.u.domain() : s.v.domain();
      const double t = c.at == 1.0 ? b : a + c.at * (b - a);
      out = c.fixed_u ? surface::iso_curve_u(s, t) : surface::iso_curve_v(s, t);
    } else {
      const BSplineSurface& s = surface_of(c.surface);
      fitted = in_recipe_words({{"CurveFitOptions::tolerance_mm", "\"tolerance_mm\""},
                                {"max_control_points", "its limit of control points"},
                                {"raise the tolerance", "raise \"tolerance_mm\""}},
                               [&] {
                                 return c.kind == "project"
                                            ? surface::project_curve(curve_of(c.source), s, c.fit)
                                            : surface::offset_along_normal(curve_of(c.source), s,
                                                                           c.distance, c.fit);
                               });
      out = fitted->curve;
    }
    rep.figures = {{"degree", static_cast<long long>(out.basis.degree)},
                   {"control_points", static_cast<long long>(out.points.rows())},
                   {"rational", out.is_rational()}};
    if (fitted) {
      rep.figures.emplace_back("max_deviation_mm", fitted->max_deviation_mm);
      rep.figures.emplace_back("tolerance_mm", c.fit.tolerance_mm);
      rep.message = c.kind + " of '" + c.source + "' on '" + c.surface + "' within " +
                    format("%.3g", fitted->max_deviation_mm) + " mm (" +
                    std::to_string(fitted->samples) + " samples)";
    }
    add_curve(c.name, std::move(out));
  }

  void sketch(const SketchDef& checked, StepReport& rep) {
    // A sketch using a stroke's fit or a reversed curve is built now, with the real curves.
    const SketchDef s =
        checked.deferred_json.empty()
            ? checked
            : rebuild_sketch(checked, [&](const std::string& n) -> const BSplineCurve* {
                const auto it = curve_index_.find(n);
                return it == curve_index_.end() ? nullptr : &result_.curves[it->second].second;
              });
    const auto solved = constraints::solve(s.sketch, s.constraints, s.solve);
    const auto& r = solved.report;
    if (!r.conflicting.empty())  // the summary lists every conflicting set, once
      throw Error(ErrorCategory::InvalidGeometry,
                  "the sketch does not solve: " + r.summary.message +
                      "; remove or change a conflicting constraint");
    if (!r.summary.converged())  // nothing conflicts: the solver stopped short
      throw Error(
          ErrorCategory::InvalidGeometry,
          "the solver stopped before the constraints hold (" + r.summary.brief() +
              "); nothing conflicts: move the drawn geometry closer to what the constraints ask");
    rep.figures = {{"max_residual", r.max_residual},
                   {"degrees_of_freedom", static_cast<long long>(r.degrees_of_freedom)},
                   {"redundant_sets", static_cast<long long>(r.redundant.size())},
                   {"constraints", static_cast<long long>(s.constraints.size())}};
    for (std::size_t k = 0; k < r.redundant.size(); ++k)  // every set, not only the first
      rep.figures.emplace_back("redundant[" + std::to_string(k) + "]", r.redundant[k].message);
    rep.message = r.summary.brief();
    for (const auto& [name, id] : s.entities) add_curve(name, sketch::curve_of(solved.sketch, id));
  }

  /// Runs a builder that takes a list of curves, its errors naming them as the recipe does:
  /// "curve #1" (the builder's index) becomes "curve \"leech\"".
  template <class F>
  static auto by_names(const std::vector<std::string>& names, const std::string& word, F build) {
    try {
      auto built = build();
      built.report.method = named(built.report.method, names, word);
      return built;
    } catch (const Error& e) {
      throw Error(e.category(), named(e.message(), names, word));
    }
  }
  std::vector<BSplineCurve> curves_named(const std::vector<std::string>& names) const {
    std::vector<BSplineCurve> out;
    for (const auto& n : names) out.push_back(curve_of(n));
    return out;
  }

  void build_surface(const SurfaceDef& def) {
    static const Words superquadric_words{{"SuperquadricOptions::tolerance_mm", "\"tolerance_mm\""},
                                          {", raise max_spans", ""}};
    if (const auto* d = std::get_if<DeformDef>(&def.build)) {
      const StackDef& stack =
          *std::find_if(data_.stacks.begin(), data_.stacks.end(),
                        [&](const StackDef& s) { return s.name == d->deformation; });
      shared_parent_ = &surface_of(d->surface), shared_composition_ = &d->composition;
      shared_.reset();
      const Needs needs = surface_needs(data_, def);
      // result_.surfaces holds the surfaces built before this one until it is added, as its key
      const auto prefix_key = [&](std::size_t k) -> std::optional<std::string> {
        if (!data_.document) return std::nullopt;
        return surface_key(data_, digests_, def, needs, result_.surfaces, k);
      };
      BSplineSurface s = deform(surface_of(d->surface), stack, d->composition, def.path, def.name,
                                !built_on(data_, def.name), bound_of(d->surface), prefix_key);
      shared_parent_ = nullptr, shared_composition_ = nullptr;
      shared_.reset();
      result_.surfaces.emplace_back(def.name, std::move(s));
      return;
    }
    timed(def.path, def.kind, [&](StepReport& rep) {
      BSplineSurface s = std::visit(
          [&](const auto& b) -> BSplineSurface {
            using T = std::decay_t<decltype(b)>;
            if constexpr (std::is_same_v<T, BSplineSurface>) {
              build_figures(surface::describe(b, "inline B-spline surface"), rep);
              return b;
            } else if constexpr (std::is_same_v<T, FillDef>) {
              const std::vector<BSplineCurve> boundary = curves_named(b.curves);
              auto built =
                  by_names(b.curves, "curve", [&] { return surface::fill(boundary, b.options); });
              build_figures(built.report, rep);
              if (b.snap) {
                // How far the ends moved: each curve end to the nearest end of another curve,
                // halved (the fill joins each corner at the midpoint of its two ends).
                double snapped = 0;
                for (std::size_t k = 0; k < boundary.size(); ++k)
                  for (const double tk :
                       {boundary[k].basis.domain().first, boundary[k].basis.domain().second}) {
                    double nearest = std::numeric_limits<double>::infinity();
                    for (std::size_t m = 0; m < boundary.size(); ++m)
                      if (m != k)
                        for (const double tm :
                             {boundary[m].basis.domain().first, boundary[m].basis.domain().second})
                          nearest = std::min(nearest, (surface::evaluate(boundary[k], tk) -
                                                       surface::evaluate(boundary[m], tm))
                                                          .norm());
                    if (std::isfinite(nearest)) snapped = std::max(snapped, nearest / 2);
                  }
                rep.figures.emplace_back("snapped_mm", snapped);
              }
              return std::move(built.surface);
            } else if constexpr (std::is_same_v<T, SkinDef>) {
              auto built = by_names(b.sections, "section", [&] {
                return surface::loft(curves_named(b.sections), b.options);
              });
              build_figures(built.report, rep);
              return std::move(built.surface);
            } else if constexpr (std::is_same_v<T, SweepDef>) {
              auto built = in_recipe_words(
                  {{"SweepOptions::max_sections = ", "a sweep's limit of "},
                   {"SweepOptions::relative_tolerance", "\"relative_tolerance\""},
                   {"SweepOptions::twist_degrees", "\"twist_degrees\""}},
                  [&] { return surface::sweep(curve_of(b.profile), curve_of(b.path), b.options); });
              build_figures(built.report, rep);
              return std::move(built.surface);
            } else if constexpr (std::is_same_v<T, RevolveDef>) {
              auto built = surface::revolve(curve_of(b.profile), b.axis, b.angle);
              build_figures(built.report, rep);
              return std::move(built.surface);
            } else if constexpr (std::is_same_v<T, SuperellipsoidDef>) {
              auto built = in_recipe_words(
                  superquadric_words, [&] { return surface::superellipsoid(b.shape, b.options); });
              build_figures(built.report, rep);
              return std::move(built.surface);
            } else if constexpr (std::is_same_v<T, SupertoroidDef>) {
              auto built = in_recipe_words(
                  superquadric_words, [&] { return surface::supertoroid(b.shape, b.options); });
              build_figures(built.report, rep);
              return std::move(built.surface);
            } else if constexpr (std::is_same_v<T, ImportDef>) {
              std::string ext = b.file.extension().string();
              for (char& ch : ext)
                ch = static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
              // A file from elsewhere: read in a child process, so a file that crashes or hangs
              // OpenCASCADE fails this step instead of the run (surface::ReadOptions).
              surface::ReadOptions guard;
              guard.isolate = true;
              auto all = (ext == ".igs" || ext == ".iges") ? surface::read_iges(b.file, guard)
                                                           : surface::read_step(b.file, guard);
              if (b.index >= static_cast<int>(all.size()))
                throw Error(ErrorCategory::InvalidArgument,
                            "index " + std::to_string(b.index) + " but \"" + b.file.string() +
                                "\" holds " + std::to_string(all.size()) +
                                " surface(s); give an index below " + std::to_string(all.size()));
              build_figures(surface::describe(all[static_cast<std::size_t>(b.index)], "import"),
                            rep);
              return std::move(all[static_cast<std::size_t>(b.index)]);
            } else if constexpr (std::is_same_v<T, RebuildDef>) {
              deform::RefitOptions o;
              o.degree = b.degree;
              o.count_u = b.count_u;
              o.count_v = b.count_v;
              o.relative_tolerance = b.relative_tolerance;
              // Without counts the net grows only where the tolerance needs it, from the
              // original's rough breakpoints alone, as the editable output does.
              const bool fixed = b.count_u > 0;
              o.keep_breakpoints = fixed;
              const auto fit = deform::refit_surface(surface_of(b.surface), o);
              const auto& r = fit.report;
              surface::BuildReport built = surface::describe(
                  fit.surface, "rebuild of '" + b.surface + "' " +
                                   (fixed ? "on " + std::to_string(b.count_u) + " x " +
                                                std::to_string(b.count_v) + " control points"
                                          : "to its tolerance"));
              built.max_deviation_mm = r.certified ? r.certified_bound_mm : r.sampled_max;
              built.samples = static_cast<int>(std::min<long>(r.samples, 1L << 30));
              build_figures(built, rep);
              rep.figures.emplace_back("certified_bound_mm", r.certified_bound_mm);
              rep.figures.emplace_back("sampled_max_mm", r.sampled_max);
              rep.figures.emplace_back("tolerance_mm", r.tolerance_mm);
              rep.message = r.brief();
              // A rebuild is the identity map: its bound adds to its parent's.
              ledger_ = bound_of(b.surface);
              ledger(rep,
                     r.certified ? r.certified_bound_mm : std::numeric_limits<double>::infinity());
              bound_of_[def.name] = ledger_;
              if (!r.summary.converged())
                throw Error(ErrorCategory::ToleranceNotMet,
                            "the rebuilt net misses its tolerance (" + r.summary.message +
                                (fixed ? "): raise \"count_u\" and \"count_v\", "
                                         "\"relative_tolerance\" or \"degree\""
                                       : "): raise \"relative_tolerance\" or \"degree\""));
              return fit.surface;
            } else if constexpr (std::is_same_v<T, MirrorDef>) {
              BSplineSurface m =
                  surface::mirrored(surface_of(b.surface), b.plane.origin, b.plane.normal);
              bound_of_[def.name] = bound_of(b.surface);  // an isometry keeps the bound
              build_figures(surface::describe(m, "mirror of '" + b.surface + "'"), rep);
              return m;
            } else {
              throw Error(ErrorCategory::Internal, "recipe run: deform handled above");
            }
          },
          def.build);
      result_.surfaces.emplace_back(def.name, std::move(s));
    });
  }

  // ---- deformation steps --------------------------------------------------------------------
  BSplineSurface compose(const deform::Deformation& d, const BSplineSurface& s,
                         const Composition& c, StepReport& rep) {
    deform::SurfaceDeformationOptions options = deformation_options(c);
    options.input_bound_mm = ledger_;
    if (options.refit) follow_shared(*options.refit, shared(), c);
    if (options.budget) follow_shared(options.budget->light, shared(), c);
    const auto r = deform::deform_surface(d, s, options);
    const auto& o = r.report.steps.front();
    ledger_ = r.report.accumulated_bound_mm;
    auto sizes = [&] {
      rep.figures.emplace_back("degree_u", static_cast<long long>(r.surface.u.degree));
      rep.figures.emplace_back("degree_v", static_cast<long long>(r.surface.v.degree));
      rep.figures.emplace_back("control_points", static_cast<long long>(r.surface.points.rows()));
    };
    if (o.method == deform::StepOutcome::Method::Exact) {
      rep.figures.emplace_back("composition", std::string("exact"));
      rep.figures.emplace_back("max_relative_deviation",
                               o.compose.max_relative_deviation);  // of size
      rep.figures.emplace_back("max_deviation_mm",
                               o.compose.max_relative_deviation * o.compose.size);
      sizes();
      rep.figures.emplace_back("exact", true);
      rep.figures.emplace_back("patches", static_cast<long long>(o.compose.patches));
      rep.figures.emplace_back("size", o.compose.size);
      rep.message += ": exact, " + o.compose.brief();
      if (ledger_ > 0) ledger_figure(rep);
    } else {
      const auto& f = o.refit;
      const double bound = f.certified ? f.certified_bound_mm : f.sampled_max;
      const bool light = o.method == deform::StepOutcome::Method::Light;
      rep.figures.emplace_back("composition", std::string(light ? "light" : "refit"));
      if (light) {
        rep.figures.emplace_back("exact_degree_u", static_cast<long long>(o.exact_size.degree_u));
        rep.figures.emplace_back("exact_degree_v", static_cast<long long>(o.exact_size.degree_v));
        if (o.exact_size.control_points > 0)
          rep.figures.emplace_back("exact_control_points",
                                   static_cast<long long>(o.exact_size.control_points));
      }
      ledger_figure(rep);
      rep.figures.emplace_back("max_relative_deviation", bound / f.size);
      rep.figures.emplace_back("max_deviation_mm", bound);
      sizes();
      rep.figures.emplace_back("exact", false);
      rep.figures.emplace_back("certified", f.certified);
      rep.figures.emplace_back("tolerance_mm", f.tolerance_mm);
      rep.figures.emplace_back("sampled_max_mm", f.sampled_max);
      rep.figures.emplace_back("size", f.size);
      rep.message += light ? ": light form (" + light_reason(o, c) + "), " + f.brief()
                           : ": refit (" + o.reason + "), " + f.brief();
      // A refit that misses its tolerance is a failure (deform_surface throws ToleranceNotMet),
      // unless the composition accepts it: then the step carries a warning.
      if (!f.summary.converged()) {
        rep.warning = true;
        rep.message += "; accepted out of tolerance (\"accept_out_of_tolerance\": true)";
      }
    }
    return r.surface;
  }

  BSplineSurface apply(const deform::Deformation& d, const BSplineSurface& s, const Composition& c,
                       StepReport& rep, Stage& stage) {
    stage.map = [d](const Eigen::Vector3d& x) {
      return std::visit(
          [&](const auto& k) -> Eigen::Vector3d { return deform::deform_point(k, x); }, d);
    };
    if (options_.preview && options_.previous)
      if (auto preview = preview_light(*options_.previous, d, s, stage.step)) {
        BSplineSurface out = std::move(preview->net);
        ledger_ = std::numeric_limits<double>::infinity();  // no certificate until let go
        preview_figures(out, rep);
        stage.light_map = std::move(preview->map);
        previewing_ = true;
        lattice_figures(d, rep);
        return out;
      }
    BSplineSurface out = compose(d, s, c, rep);
    lattice_figures(d, rep);
    return out;
  }

  BSplineSurface apply(const StyleDef& d, const BSplineSurface& s, const Composition&,
                       StepReport& rep, Stage&) {
    StyleStep out = style_step(d, s, d.bound.empty() ? nullptr : &curve_of(d.bound),
                               curve_of(d.target), options_, rep);
    if (out.previewed) previewing_ = true;
    if (ledger_ > 0) {  // the style of a light input is not the style of its exact reference
      ledger_ = std::numeric_limits<double>::infinity();
      ledger_figure(rep);
      rep.message +=
          "; its input is a light form, so its distance from the exact reference is "
          "not bounded";
    }
    return std::move(out.surface);
  }

  BSplineSurface apply(const DirectDef& d, const BSplineSurface& s, const Composition& c,
                       StepReport& rep, Stage& stage) {
    std::vector<deform::PointMove> moves;
    for (const auto& m : d.moves) {
      Eigen::Vector3d x = m.point;
      if (m.on_surface) {
        const auto [u0, u1] = s.u.domain();
        const auto [v0, v1] = s.v.domain();
        if (m.point.x() < u0 || m.point.x() > u1 || m.point.y() < v0 || m.point.y() > v1)
          throw Error(ErrorCategory::OutOfDomain,
                      "surface_point (" + format("%.17g", m.point.x()) + ", " +
                          format("%.17g", m.point.y()) + ") is outside the surface's domain [" +
                          format("%g", u0) + ", " + format("%g", u1) + "] x [" + format("%g", v0) +
                          ", " + format("%g", v1) + "]; give parameters inside it");
        x = surface::evaluate(s, m.point.x(), m.point.y());
      }
      moves.push_back({x, m.to});
    }
    deform::Deformation lattice;
    deform::DirectManipulationReport r;
    std::visit(
        [&](const auto& lat) {
          auto solved = deform::manipulate(lat, moves, d.options);
          r = solved.report;
          lattice = std::move(solved.lattice);
        },
        d.lattice);
    rep.figures = {{"requested", static_cast<long long>(r.requested)},
                   {"rank", static_cast<long long>(r.rank)},
                   {"feasible", r.feasible},
                   {"residual", r.residual},
                   {"achieved_max_error", r.achieved_max_error},
                   {"displacement_norm", r.displacement_norm}};
    rep.message += ": " + r.summary.message;
    if (!r.feasible) {  // moves the lattice cannot meet: a failure unless accepted
      if (!d.accept_out_of_tolerance)
        throw Error(ErrorCategory::ToleranceNotMet,
                    "the lattice cannot meet every move (" + r.summary.message +
                        "): free more control points (fewer \"locked\"), use a finer lattice, or "
                        "ask for fewer "
                        "moves; to keep the least-squares answer anyway, set "
                        "\"accept_out_of_tolerance\": true on "
                        "this step");
      rep.warning = true;
    }
    stage.map = [lattice](const Eigen::Vector3d& x) {
      return std::visit(
          [&](const auto& k) -> Eigen::Vector3d { return deform::deform_point(k, x); }, lattice);
    };
    BSplineSurface out = compose(lattice, s, c, rep);
    lattice_figures(lattice, rep);
    return out;
  }
};

}  // namespace

RunResult run_recipe(const Recipe& recipe, const RunOptions& options) {
  if (!recipe.data)
    throw Error(ErrorCategory::InvalidArgument,
                "run_recipe: empty recipe; load or parse one first");
  const auto t0 = Clock::now();
  RunResult result;
  result.recipe = recipe.data->name;
  Runner runner(*recipe.data, options, result);
  runner.curves();
  runner.surfaces();
  runner.exports();
  runner.models();
  result.seconds = seconds_since(t0);
  return result;
}

void conform_export(ExportResult& e, const Recipe& recipe, const RunResult& run) {
  if (!recipe.data)
    throw Error(ErrorCategory::InvalidArgument,
                "conform_export: empty recipe; load or parse one first");
  RunResult scratch;  // the runner reads the run's surfaces from it
  scratch.surfaces = run.surfaces;
  const RunOptions quiet;
  Runner runner(*recipe.data, quiet, scratch);
  runner.seed_bounds(run.bounds);
  StepReport report;
  runner.conform(e, report);
}

RunResult deform_surfaces(const Recipe& recipe, const std::vector<BSplineSurface>& surfaces,
                          std::string_view stem, std::string_view deformation,
                          const RunOptions& options) {
  if (!recipe.data)
    throw Error(ErrorCategory::InvalidArgument,
                "deform_surfaces: empty recipe; load or parse one first");
  const RecipeData& d = *recipe.data;
  const StackDef* stack = &pick_stack(d, deformation);
  if (surfaces.empty())
    throw Error(ErrorCategory::InvalidArgument, "deform_surfaces: no surfaces given");
  const auto t0 = Clock::now();
  RunResult result;
  result.recipe = d.name;
  Runner runner(d, options, result);
  runner.curves();  // the curves its style steps use
  ExportResult x;
  x.name = std::string(stem);
  x.formats = d.exports.empty() ? std::vector<std::string>{"step", "iges", "glb"}
                                : d.exports.front().formats;
  x.schema = d.exports.empty() ? "AP214" : d.exports.front().schema;
  for (std::size_t k = 0; k < surfaces.size(); ++k) {
    const std::string name = std::string(stem) + "-" + std::to_string(k);
    BSplineSurface s =
        runner.deform(surfaces[k], *stack, d.composition, "input[" + std::to_string(k) + "]", name);
    result.surfaces.emplace_back(name, s);
    x.surface_names.push_back(name);
    x.surfaces.push_back(std::move(s));
  }
  result.exports.push_back(std::move(x));
  result.seconds = seconds_since(t0);
  return result;
}

}  // namespace clay::recipe
