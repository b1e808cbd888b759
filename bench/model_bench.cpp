// Whole models (issue #20): read, deform exactly, validate and write a 200-face solid (a plate
// 200 x 200 x 10 with filleted corners and 190 through holes, built by OpenCASCADE and written as
// STEP), phase by phase and as one pipeline (read, deform, brep::validate, write without
// BRepCheck; target: under 1 s on 2 cores). The reference, in the
// same run: OpenCASCADE's own affine map of the same solid, BRepBuilderAPI_GTransform (with
// geometry copies), against deform_model with an affine lattice.
#include <clay/brep/continuity.hpp>
#include <clay/brep/volume.hpp>
#include <clay/deform/model_deformation.hpp>
#include <clay/deform/model_derivatives.hpp>
#include <clay/deform/regular.hpp>
#include <clay/occt/model_exchange.hpp>

#include <benchmark/benchmark.h>

#include <algorithm>
#include <filesystem>
#include <string>
#include <vector>

#include "occt_test_models.hpp"

namespace fs = std::filesystem;
using namespace clay;

namespace {

const fs::path& plate_file() {
  static const fs::path file = [] {
    const fs::path f = fs::temp_directory_path() / "clayform-bench-plate.step";
    surface::occt_reference::write_test_model(surface::occt_reference::TestModel::HolePlate, f);
    return f;
  }();
  return file;
}

const brep::Model& plate() {
  static const brep::Model m = brep::read_model(plate_file()).model;
  return m;
}

deform::Frame around_plate() {
  deform::Frame f;
  f.origin = {-5, -5, -5};
  f.s = {210, 0, 0};
  f.t = {0, 210, 0};
  f.u = {0, 0, 20};
  return f;
}

/// A trilinear lattice with one top corner raised: not affine (total degree 3).
deform::DeformationStack bent_stack() {
  auto lattice = deform::make_bezier_lattice(around_plate(), {1, 1, 1});
  lattice.points.row(lattice.index(1, 1, 1)) += Eigen::RowVector3d(4, 6, 12);
  deform::DeformationStack stack;
  stack.steps.push_back({lattice, "raise a corner", true});
  return stack;
}

/// The affine map x -> A x + b as a trilinear lattice, and as the matrix [A | b].
const Eigen::Matrix<double, 3, 4>& affine_map() {
  static const Eigen::Matrix<double, 3, 4> a = [] {
    Eigen::Matrix<double, 3, 4> m;
    m << 1.05, 0.02, 0.0, 1.0, 0.0, 0.97, 0.01, -2.0, 0.03, 0.0, 1.1, 0.5;
    return m;
  }();
  return a;
}

deform::DeformationStack affine_stack() {
  auto lattice = deform::make_bezier_lattice(around_plate(), {1, 1, 1});
  for (Eigen::Index r = 0; r < lattice.points.rows(); ++r)
    lattice.points.row(r) =
        (affine_map().leftCols<3>() * lattice.points.row(r).transpose() + affine_map().col(3))
            .transpose();
  deform::DeformationStack stack;
  stack.steps.push_back({lattice, "affine", true});
  return stack;
}

void faces_counter(benchmark::State& state) {
  state.counters["faces"] = static_cast<double>(brep::counts(plate()).faces);
  state.counters["edges"] = static_cast<double>(brep::counts(plate()).edges);
}

void BM_Read(benchmark::State& state) {
  plate_file();  // built once, outside the timing
  for (auto _ : state) benchmark::DoNotOptimize(brep::read_model(plate_file()));
  faces_counter(state);
}

void BM_DeformExact(benchmark::State& state) {
  plate();  // read once, outside the timing
  const auto stack = bent_stack();
  for (auto _ : state) benchmark::DoNotOptimize(deform::deform_model(stack, plate()));
  const auto r = deform::deform_model(stack, plate()).report;
  state.counters["faces_exact"] = r.faces_exact;
  state.counters["max_edge_gap_mm"] = r.max_edge_gap_mm;
  faces_counter(state);
}

void BM_DeformAffine(benchmark::State& state) {
  plate();  // read once, outside the timing
  const auto stack = affine_stack();
  for (auto _ : state) benchmark::DoNotOptimize(deform::deform_model(stack, plate()));
  faces_counter(state);
}

void BM_OcctGTransformAffine(benchmark::State& state) {
  plate();
  const surface::occt_reference::GTransformReference reference(plate_file());
  for (auto _ : state) benchmark::DoNotOptimize(reference.transform(affine_map()));
  faces_counter(state);
}

void BM_ValidateInvariants(benchmark::State& state) {
  plate();  // read once, outside the timing
  const auto deformed = deform::deform_model(bent_stack(), plate()).model;
  for (auto _ : state) benchmark::DoNotOptimize(brep::problems(deformed));
  faces_counter(state);
}

/// How the faces meet along every shared edge (brep::edge_continuity, issue #38): deform_model
/// measures it twice, before and after, so this is its share of BM_DeformExact.
void BM_EdgeContinuity(benchmark::State& state) {
  plate();  // read once, outside the timing
  for (auto _ : state) benchmark::DoNotOptimize(brep::edge_continuity(plate()));
  faces_counter(state);
  state.counters["shared_edges"] = static_cast<double>(brep::edge_continuity(plate()).edges.size());
}

/// brep::volume_mm3 of real files (tests/data/cad) read once: Alibre's assembly (8 bodies with
/// rational spheres: adaptive inner integrals) and NX 9's B-spline bracket. The inner integral
/// along u at fixed v sums the isocurve at v made once per integral (2026-12-06: the pointwise
/// surface derivatives there were three quarters of reading and checking these files).
void BM_Volume(benchmark::State& state) {
  static const char* const files[] = {"alibre_s1_assembly_ap214.stp",
                                      "nx9_281390_bsplines_sphere_ap214.stp"};
  const brep::Model m =
      brep::read_model(fs::path(CLAY_BENCH_CAD_DIR) / files[state.range(0)]).model;
  for (auto _ : state) benchmark::DoNotOptimize(brep::volume_mm3(m));
  state.SetLabel(files[state.range(0)]);
  state.counters["faces"] = static_cast<double>(m.faces.size());
}

void BM_ValidateBRepCheck(benchmark::State& state) {
  plate();  // read once, outside the timing
  const auto deformed = deform::deform_model(bent_stack(), plate()).model;
  for (auto _ : state) benchmark::DoNotOptimize(brep::check_model(deformed));
  faces_counter(state);
}

/// Writing with and without write_model's own check (BRepCheck and volumes).
void BM_Write(benchmark::State& state) {
  plate();  // read once, outside the timing
  const auto deformed = deform::deform_model(bent_stack(), plate()).model;
  const fs::path out = fs::temp_directory_path() / "clayform-bench-plate-out.step";
  brep::ModelWriteOptions options;
  options.check = state.range(0) != 0;
  for (auto _ : state) benchmark::DoNotOptimize(brep::write_model(deformed, out, options));
  faces_counter(state);
}

/// The whole job: read, deform exactly, validate (invariants), write.
void BM_Pipeline(benchmark::State& state) {
  plate_file();
  const auto stack = bent_stack();
  const fs::path out = fs::temp_directory_path() / "clayform-bench-plate-pipeline.step";
  for (auto _ : state) {
    const auto read = brep::read_model(plate_file());
    const auto deformed = deform::deform_model(stack, read.model);
    brep::validate(deformed.model);
    brep::ModelWriteOptions options;
    options.check = false;  // validated above
    benchmark::DoNotOptimize(brep::write_model(deformed.model, out, options));
  }
  faces_counter(state);
}

const brep::Model& filleted_block() {
  static const brep::Model m = [] {
    const fs::path f = fs::temp_directory_path() / "clayform-bench-block.step";
    surface::occt_reference::write_test_model(surface::occt_reference::TestModel::FilletedBlock, f);
    return brep::read_model(f).model;
  }();
  return m;
}

/// Issue #38 step 7, before and after in one run: the filleted block twisted about z at
/// 0.005 rad/mm, each face refitted within 1 % of its size, alone (arg 0: edge_gap_mm =
/// edge_angle_deg = 0, as before) or following its edges (arg 1: the defaults, 0.0005 mm and
/// 0.008 deg). Counters: the fillets' largest tangent-plane angle and the largest gap after,
/// and the time per refitted face.
void BM_TwistBlockEdges(benchmark::State& state) {
  const brep::Model& block = filleted_block();
  deform::Twist twist;
  twist.angle = {0, 0.005};
  deform::DeformationStack stack;
  stack.steps.push_back({twist, "twist", true});
  deform::ModelDeformationOptions options;
  deform::RefitOptions refit;
  refit.relative_tolerance = 0.01;
  options.surface.refit = refit;
  if (state.range(0) == 0) options.edge_gap_mm = options.edge_angle_deg = 0;
  for (auto _ : state) benchmark::DoNotOptimize(deform::deform_model(stack, block, options));
  const auto r = deform::deform_model(stack, block, options).report;
  double fillet = 0;
  for (std::size_t k = 0; k < r.continuity_after.edges.size(); ++k) {
    const auto& was = r.continuity_before.edges[k];
    if (was.face_a != was.face_b && was.angle_deg < 1e-6)
      fillet = std::max(fillet, r.continuity_after.edges[k].angle_deg);
  }
  state.counters["fillet_angle_deg"] = fillet;
  state.counters["max_gap_mm"] = r.continuity_after.max_gap_mm;
  state.counters["faces_refit"] = r.faces_refit;
  state.counters["per_face"] = benchmark::Counter(
      r.faces_refit, benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}

}  // namespace

// Shape optimisation on the 200-face plate (issue #41): the model's Jacobian with respect to a
// (2, 2, 1) lattice's 18 points, its transpose product (an adjoint's step), the model at other
// points, the mass properties' gradients and a volume-keeping drag; the references in the same
// run: deform_model with the same lattice (composing again) and brep::volume_mm3.
deform::BezierLattice plate_lattice() {
  auto lattice = deform::make_bezier_lattice(around_plate(), {2, 2, 1});
  lattice.points.row(lattice.index(1, 1, 1)) += Eigen::RowVector3d(3, -2, 6);
  lattice.points.row(lattice.index(2, 0, 1)) += Eigen::RowVector3d(0, 4, -2);
  return lattice;
}

const deform::ModelJacobian& plate_jacobian() {
  static const deform::ModelJacobian j = deform::model_jacobian(plate_lattice(), plate());
  return j;
}

void jacobian_counters(benchmark::State& state) {
  long rows = 0, entries = 0;
  for (const auto& f : plate_jacobian().faces) {
    rows += f.rows();
    entries += f.nonZeros();
  }
  state.counters["control_points"] = static_cast<double>(rows);
  state.counters["nonzeros"] = static_cast<double>(entries);
  faces_counter(state);
}

void BM_ModelJacobian(benchmark::State& state) {
  const auto lattice = plate_lattice();
  for (auto _ : state) benchmark::DoNotOptimize(deform::model_jacobian(lattice, plate()));
  jacobian_counters(state);
}

void BM_ModelJacobianReferenceDeform(benchmark::State& state) {
  deform::DeformationStack stack;
  stack.steps.push_back({plate_lattice(), "lattice", true});
  plate();
  for (auto _ : state) benchmark::DoNotOptimize(deform::deform_model(stack, plate()));
  faces_counter(state);
}

void BM_ModelJacobianTransposeProduct(benchmark::State& state) {
  const auto& j = plate_jacobian();
  std::vector<surface::Points3> g;
  for (const auto& f : j.faces) g.push_back(surface::Points3::Ones(f.rows(), 3));
  for (auto _ : state) {
    surface::Points3 out = surface::Points3::Zero(j.lattice_points, 3);
    for (std::size_t f = 0; f < g.size(); ++f) out += j.faces[f].transpose() * g[f];
    benchmark::DoNotOptimize(out);
  }
  jacobian_counters(state);
}

void BM_DeformedModel(benchmark::State& state) {
  const auto& j = plate_jacobian();
  surface::Points3 points = plate_lattice().points;
  points(0, 2) += 1;
  for (auto _ : state) benchmark::DoNotOptimize(deform::deformed_model(j, points));
  jacobian_counters(state);
}

void BM_MassPropertyGradients(benchmark::State& state) {
  const auto& j = plate_jacobian();
  for (auto _ : state) benchmark::DoNotOptimize(deform::mass_property_gradients(j));
  jacobian_counters(state);
}

void BM_MassPropertyReferenceVolume(benchmark::State& state) {
  const auto& j = plate_jacobian();
  for (auto _ : state) benchmark::DoNotOptimize(brep::volume_mm3(j.model));
  jacobian_counters(state);
}

void BM_KeepVolumeDrag(benchmark::State& state) {
  const auto& j = plate_jacobian();
  deform::KeptProperties keep;
  keep.volume_mm3 = brep::volume_mm3(j.model);
  const int dragged = static_cast<int>(plate_lattice().index(1, 2, 1));
  keep.held = {dragged};
  surface::Points3 moved = plate_lattice().points;
  moved.row(dragged) += Eigen::RowVector3d(2, 3, 4);
  int iterations = 0;
  for (auto _ : state) iterations = deform::keep_properties(j, moved, keep).iterations;
  state.counters["newton_steps"] = iterations;
  jacobian_counters(state);
}

// The area with its bound and gradient (adaptive inner rule: |n| is not polynomial), against the
// surface area alone and against the volume's fixed rule above.
void BM_SurfaceAreaGradient(benchmark::State& state) {
  const auto& j = plate_jacobian();
  double bound = 0;
  double area = 0;
  for (auto _ : state) {
    const auto g = deform::surface_area_gradient(j);
    bound = g.value.bound_mm2;
    area = g.value.area_mm2;
  }
  state.counters["bound_mm2"] = bound;
  state.counters["area_mm2"] = area;
  jacobian_counters(state);
}

void BM_SurfaceArea(benchmark::State& state) {
  const auto& j = plate_jacobian();
  for (auto _ : state) benchmark::DoNotOptimize(brep::surface_area(j.model));
  jacobian_counters(state);
}

// A drag keeping the volume with the plate's bottom face fixed and the middle plane x = const a
// symmetry plane: the linear constraints' QR and the projected Newton steps.
void BM_KeepVolumeFixedSymmetricDrag(benchmark::State& state) {
  // The lattice at rest (symmetric about its middle plane), not plate_lattice's moved one.
  const deform::BezierLattice lattice = deform::make_bezier_lattice(around_plate(), {2, 2, 1});
  static const deform::ModelJacobian j = deform::model_jacobian(lattice, plate());
  deform::KeptProperties keep;
  keep.volume_mm3 = brep::volume_mm3(j.model);
  int bottom = 0;
  double lowest = 1e300;
  for (std::size_t f = 0; f < j.model.faces.size(); ++f)
    if (j.faces[f].nonZeros() > 0 && j.model.faces[f].surface.points.col(2).maxCoeff() < lowest) {
      lowest = j.model.faces[f].surface.points.col(2).maxCoeff();
      bottom = static_cast<int>(f);
    }
  keep.fixed_faces = {bottom};
  const Eigen::Vector3d middle = j.points.colwise().mean().transpose();
  keep.symmetry_planes = {{middle, lattice.frame.s}};
  const int dragged = static_cast<int>(lattice.index(1, 2, 1));
  keep.held = {dragged};
  surface::Points3 moved = lattice.points;
  moved.row(dragged) += Eigen::RowVector3d(0, 3, 4);
  int iterations = 0;
  for (auto _ : state) iterations = deform::keep_properties(j, moved, keep).iterations;
  state.counters["newton_steps"] = iterations;
  jacobian_counters(state);
}

BENCHMARK(BM_ModelJacobian)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_ModelJacobianReferenceDeform)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_ModelJacobianTransposeProduct)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_DeformedModel)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_MassPropertyGradients)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_MassPropertyReferenceVolume)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_KeepVolumeDrag)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_SurfaceAreaGradient)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_SurfaceArea)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_KeepVolumeFixedSymmetricDrag)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_TwistBlockEdges)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Read)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_DeformExact)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_DeformAffine)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_OcctGTransformAffine)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_ValidateInvariants)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_ValidateBRepCheck)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Volume)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_EdgeContinuity)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Write)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Pipeline)->Unit(benchmark::kMillisecond);
BENCHMARK_MAIN();
