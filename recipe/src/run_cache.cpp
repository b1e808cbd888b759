// RunCache (issue #40): results kept between runs under keys of their definitions and inputs,
// least recently used dropped first beyond the capacity.
#include "run_cache.hpp"

#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <list>
#include <mutex>
#include <unordered_map>

namespace clay::recipe {

struct RunCache::Impl {
  explicit Impl(std::size_t capacity) : capacity_bytes(capacity) {}
  struct Slot {
    std::shared_ptr<const detail::CacheEntry> entry;
    std::size_t bytes = 0;
    std::list<std::string>::iterator recent;  // its place in `order`
  };
  std::size_t capacity_bytes;
  mutable std::mutex mutex;
  std::unordered_map<std::string, Slot> slots;
  std::list<std::string> order;  // most recently used first
  Counts counts;
  // Style editors for drag previews, most recent first (CacheAccess::style_editor); a few
  // only: each holds its exact nets' factorizations.
  struct Editor {
    surface::BSplineCurve bound;
    deform::StyleOptions options;
    std::shared_ptr<deform::StyleEditor> editor;
  };
  std::list<Editor> editors;
  static constexpr std::size_t max_editors = 4;
  // Stroke fits, most recent first, each under its stroke's and settings' bytes (fit_key).
  struct Fit {
    std::string key;
    double corner_angle, corner_window;
    sketch::StrokeFit fit;
  };
  std::list<Fit> fits;
  static constexpr std::size_t max_fits = 8;
};

namespace {

template <class T>
void append_bytes(std::string& key, const T& value) {
  key.append(reinterpret_cast<const char*>(&value), sizeof value);
}

/// Every input of sketch::fit_stroke as bytes but the corner settings (RunCache::fit_stroke
/// compares those itself).
std::string fit_key(const sketch::Stroke& stroke, const sketch::FitOptions& o) {
  std::string key;
  key.reserve(static_cast<std::size_t>(stroke.points.size()) * sizeof(double) + 160);
  append_bytes(key, stroke.points.rows());
  key.append(reinterpret_cast<const char*>(stroke.points.data()),
             static_cast<std::size_t>(stroke.points.size()) * sizeof(double));
  append_bytes(key, stroke.plane.has_value());
  if (stroke.plane)
    for (const Eigen::Vector3d* v :
         {&stroke.plane->origin, &stroke.plane->x_axis, &stroke.plane->y_axis})
      for (int i = 0; i < 3; ++i) append_bytes(key, (*v)[i]);
  for (const double d : {o.tolerance_mm, o.fairness, o.closing_ratio}) append_bytes(key, d);
  for (const int i :
       {o.degree, o.fairness_reductions, o.max_control_points, o.max_iterations, o.end_samples})
    append_bytes(key, i);
  append_bytes(key, o.drop_duplicates);
  return key;
}

}  // namespace

RunCache::RunCache(std::size_t capacity_bytes) : impl_(std::make_unique<Impl>(capacity_bytes)) {}
RunCache::~RunCache() = default;

RunCache::Counts RunCache::counts() const {
  const std::lock_guard<std::mutex> lock(impl_->mutex);
  return impl_->counts;
}

void RunCache::clear() {
  const std::lock_guard<std::mutex> lock(impl_->mutex);
  impl_->slots.clear();
  impl_->order.clear();
  impl_->editors.clear();
  impl_->fits.clear();
  impl_->counts = {};
}

sketch::StrokeFit RunCache::fit_stroke(const sketch::Stroke& stroke,
                                       const sketch::FitOptions& options) {
  std::string key = fit_key(stroke, options);
  // The corner settings only choose the corners (a turn by more than corner_angle, measured over
  // corner_window): a fit that found none is the fit at any larger angle (the studio asks at
  // 50 degrees, a recipe stroke without "pieces" is fitted at 180, never split).
  auto same = [&](const Impl::Fit& f) {
    if (f.key != key) return false;
    if (f.corner_angle == options.corner_angle && f.corner_window == options.corner_window)
      return true;
    return f.fit.corners.empty() &&
           (options.corner_angle >= 180.0 ||
            (options.corner_angle >= f.corner_angle && options.corner_window == f.corner_window));
  };
  {
    const std::lock_guard<std::mutex> lock(impl_->mutex);
    auto& fits = impl_->fits;
    for (auto it = fits.begin(); it != fits.end(); ++it)
      if (same(*it)) {
        fits.splice(fits.begin(), fits, it);  // the most recent
        ++impl_->counts.fits_reused;
        return fits.front().fit;
      }
  }
  // Fitted outside the lock: other threads' runs go on meanwhile.
  sketch::StrokeFit fit = sketch::fit_stroke(stroke, options);
  const std::lock_guard<std::mutex> lock(impl_->mutex);
  impl_->fits.push_front({std::move(key), options.corner_angle, options.corner_window, fit});
  if (impl_->fits.size() > Impl::max_fits) impl_->fits.pop_back();
  return fit;
}

namespace detail {

std::string definition_text(const DocumentJson& doc, const char* section, const std::string& name) {
  const auto s = doc.root->find(section);
  if (s == doc.root->end() || !s->is_object()) return {};
  const auto n = s->find(name);
  return n == s->end() ? std::string() : n->dump();
}

std::string digest(const std::string& key) {
  // Two independent 64-bit hashes: FNV-1a and a multiply-xorshift mix of 8-byte words. A digest
  // stands for a step's whole key inside the keys built on it (a step itself is looked up by its
  // full key): a wrong entry would need two different inputs with one 128-bit digest.
  std::uint64_t fnv = 14695981039346656037ull;
  for (const unsigned char c : key) {
    fnv ^= c;
    fnv *= 1099511628211ull;
  }
  std::uint64_t mix = 0x9e3779b97f4a7c15ull ^ key.size();
  for (std::size_t k = 0; k < key.size(); k += 8) {
    std::uint64_t w = 0;
    for (std::size_t j = 0; j < 8 && k + j < key.size(); ++j)
      w |= static_cast<std::uint64_t>(static_cast<unsigned char>(key[k + j])) << (8 * j);
    mix ^= w + 0x9e3779b97f4a7c15ull + (mix << 6) + (mix >> 2);
    mix *= 0xff51afd7ed558ccdull;
    mix ^= mix >> 33;
  }
  char out[33];
  std::snprintf(out, sizeof out, "%016llx%016llx", static_cast<unsigned long long>(fnv),
                static_cast<unsigned long long>(mix));
  return out;
}

std::size_t entry_bytes(const CacheEntry& e) {
  auto curve = [](const surface::BSplineCurve& c) {
    return static_cast<std::size_t>(c.points.size() + c.weights.size()) * sizeof(double) +
           c.basis.knots.size() * sizeof(double);
  };
  auto net = [](const surface::BSplineSurface& s) {
    return static_cast<std::size_t>(s.points.size() + s.weights.size()) * sizeof(double) +
           (s.u.knots.size() + s.v.knots.size()) * sizeof(double);
  };
  std::size_t bytes = sizeof(CacheEntry);
  for (const auto& [name, c] : e.curves) bytes += name.size() + curve(c);
  for (const auto& [name, s] : e.surfaces) bytes += name.size() + net(s);
  for (const Stage& st : e.stages) bytes += net(st.before) + net(st.after) + 256;
  for (const StepReport& r : e.steps) bytes += r.message.size() + 64 * (r.figures.size() + 2);
  return bytes;
}

void note_digests(Digests& g, const CacheEntry& e, const std::string& d) {
  for (const auto& c : e.curves) g.curve[c.first] = d + "/" + c.first;
  for (const auto& s : e.surfaces) g.surface[s.first] = d;
}

std::optional<std::string> own_key(const RecipeData& data, const Digests& g, const char* section,
                                   const std::string& name, const Needs& needs) {
  std::string k = std::string(section) + "\n" + definition_text(*data.document, section, name);
  for (const auto& c : needs.curves) {
    const auto it = g.curve.find(c);
    if (it == g.curve.end()) return std::nullopt;
    k += "\ncurve " + c + " " + it->second;
  }
  for (const auto& s : needs.surfaces) {
    const auto it = g.surface.find(s);
    if (it == g.surface.end()) return std::nullopt;
    k += "\nsurface " + s + " " + it->second;
  }
  return k;
}

std::optional<std::string> surface_key(
    const RecipeData& data, const Digests& g, const SurfaceDef& def, const Needs& needs,
    const std::vector<std::pair<std::string, surface::BSplineSurface>>& before,
    std::optional<std::size_t> stack_prefix) {
  std::optional<std::string> k = own_key(data, g, "surfaces", def.name, needs);
  if (!k) return k;
  const auto comp = data.document->root->find("composition");
  *k += "\ncomposition " + (comp == data.document->root->end() ? std::string() : comp->dump());
  if (const auto* d = std::get_if<DeformDef>(&def.build)) {
    if (!stack_prefix) {
      *k += "\nstack " + definition_text(*data.document, "deformations", d->deformation);
    } else {
      // the first k steps as written (the checker took the stack for an array of steps)
      const auto section = data.document->root->find("deformations");
      if (section == data.document->root->end() || !section->is_object()) return std::nullopt;
      const auto steps = section->find(d->deformation);
      if (steps == section->end() || !steps->is_array() || *stack_prefix > steps->size())
        return std::nullopt;
      *k += "\nstack prefix " + std::to_string(*stack_prefix);
      for (std::size_t i = 0; i < *stack_prefix; ++i) *k += "\n" + (*steps)[i].dump();
    }
    *k += built_on(data, def.name) ? "\nbuilt on" : "\nfinal";
    *k += "\nafter";
    for (const auto& built : before) {
      const auto it = g.surface.find(built.first);
      if (it == g.surface.end()) return std::nullopt;
      *k += " " + built.first + " " + it->second;
    }
  }
  if (const auto* b = std::get_if<ImportDef>(&def.build)) {
    std::error_code size_error, time_error;
    const auto size = std::filesystem::file_size(b->file, size_error);
    const auto time = std::filesystem::last_write_time(b->file, time_error);
    if (size_error || time_error) return std::nullopt;
    *k += "\nfile " + b->file.string() + " " + std::to_string(size) + " " +
          std::to_string(time.time_since_epoch().count());
  }
  return k;
}

std::shared_ptr<const CacheEntry> CacheAccess::find(RunCache& cache, const std::string& key) {
  RunCache::Impl& c = *cache.impl_;
  const std::lock_guard<std::mutex> lock(c.mutex);
  const auto it = c.slots.find(key);
  if (it == c.slots.end()) return nullptr;
  c.order.splice(c.order.begin(), c.order, it->second.recent);
  ++c.counts.reused;
  return it->second.entry;
}

void CacheAccess::keep(RunCache& cache, const std::string& key, CacheEntry entry) {
  const std::size_t bytes = entry_bytes(entry) + key.size();
  RunCache::Impl& c = *cache.impl_;
  const std::lock_guard<std::mutex> lock(c.mutex);
  if (bytes > c.capacity_bytes || c.slots.count(key)) return;
  while (!c.order.empty() && c.counts.bytes + bytes > c.capacity_bytes) {
    const auto last = c.slots.find(c.order.back());
    c.counts.bytes -= last->second.bytes;
    c.slots.erase(last);
    c.order.pop_back();
    ++c.counts.evicted;
    --c.counts.entries;
  }
  c.order.push_front(key);
  c.slots.emplace(key, RunCache::Impl::Slot{std::make_shared<const CacheEntry>(std::move(entry)),
                                            bytes, c.order.begin()});
  c.counts.bytes += bytes;
  ++c.counts.kept;
  ++c.counts.entries;
}

std::shared_ptr<deform::StyleEditor> CacheAccess::style_editor(
    RunCache& cache, const surface::BSplineSurface& parent, const surface::BSplineCurve& bound,
    const deform::StyleOptions& options) {
  RunCache::Impl& c = *cache.impl_;
  const std::lock_guard<std::mutex> lock(c.mutex);
  for (auto it = c.editors.begin(); it != c.editors.end(); ++it)
    if (it->options == options && surface::identical(it->bound, bound) &&
        surface::identical(it->editor->parent(), parent)) {
      c.editors.splice(c.editors.begin(), c.editors, it);  // the most recent
      return c.editors.front().editor;
    }
  auto editor = std::make_shared<deform::StyleEditor>(
      parent, deform::influence_factors(parent, bound, options), options);
  c.editors.push_front({bound, options, editor});
  if (c.editors.size() > RunCache::Impl::max_editors) c.editors.pop_back();
  return editor;
}

}  // namespace detail
}  // namespace clay::recipe
