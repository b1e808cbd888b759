#pragma once
/// Deformation of whole B-rep models (issue #20): every face, edge and vertex of a brep::Model
/// through a deformation stack, so that trimmed faces stay trimmed, shared edges stay shared and
/// solids stay closed.
///
/// Exact composition F∘S keeps a face's (u, v) parametrization, so its pcurves stay valid bit for
/// bit; each edge's curve composes exactly as F∘C on the same parameter t (as the ruled surface
/// C(t) × [0, 1], row 0 of the composed net), and F(S(pcurve(t))) = F(C(t)) wherever
/// S(pcurve(t)) = C(t). Vertices are mapped by the stack's pointwise deformation. The free edges
/// of wire bodies compose the same way, when the whole model is deformed (options.faces empty).
/// - A face whose control points all lie on the outer side of one face of every enabled
///   lattice's box, or whose lattices are undisplaced, is untouched: kept bit for bit (the FFD
///   is the identity outside its lattice), and keeps its type (Face::elementary: a plane is still
///   written as a plane). So are the edges and vertices only untouched faces use.
/// - Where exact composition is impossible (a face crossing a lattice's boundary or a knot plane
///   off its iso-lines, twist, bend, extended lattices, a degree above max_degree), the face and
///   its edges are refitted on the same (u, v) and t with a certified bound when
///   options.surface.refit allows it; edge and vertex tolerances then grow by the bounds. A
///   refitted face follows the exact result along its edges within edge_gap_mm and
///   edge_angle_deg, so its neighbours keep the continuity the exact result has there.
/// - A mirroring stack (det DF < 0) turns solids inside out: detected by the sign of each solid's
///   volume, whose faces are then reversed.
/// - An assembly is flattened first (brep::flattened): each placed instance deforms on its own.
#include <clay/brep/continuity.hpp>
#include <clay/brep/model.hpp>
#include <clay/deform/export.hpp>
#include <clay/deform/receiver.hpp>
#include <clay/deform/stack.hpp>
#include <clay/deform/surface_deformation.hpp>
#include <clay/summary.hpp>

#include <optional>
#include <string>
#include <vector>

namespace clay::deform {

/// Settings of deform_model.
struct CLAY_DEFORM_API ModelDeformationOptions {
  /// Composition and (optional) refit of each face and edge; without `surface.refit`, a face that
  /// cannot be composed exactly is an error naming it.
  SurfaceDeformationOptions surface;
  /// Largest degree of a result (1 to 25, the exchange limit). An exact face or edge above it is
  /// refitted (certified) when surface.refit is given, else refused (DegreeLimit) naming it.
  int max_degree = 25;
  /// The faces to deform, as indices into flattened(model).faces (the model's own faces when it
  /// has no assembly); empty: every face. The others are kept as they are, so an edge a chosen
  /// face shares with a kept one must stay where it is: a stack that moves it by more than its
  /// tolerance is refused (InvalidArgument naming both faces and the edge).
  std::vector<int> faces;
  /// A refitted face is fitted with its edges (issue #38 step 7; RefitOptions::matched_curves):
  /// along every edge it follows the exact result within edge_gap_mm and its normal within
  /// edge_angle_deg, so two faces refitted alone meet within twice these wherever the exact
  /// result's faces meet: a fillet's tangent edge stays tangent. The defaults are half the
  /// class-A fillet figures (0.001 mm, 0.016 deg). Both 0: faces fitted to their tolerance
  /// alone (each edge opens by however much its faces' fits wander). Sampled along the edges,
  /// not certified; the edges' curves are refitted within edge_gap_mm too. What an edge keeps
  /// follows the source (MatchedCurve::order): the angle where it is tangent within 1 deg, the
  /// curvature too where its relative curvature jump is <= 5 %, the position alone where it is
  /// sharp; a seam is tied (continuous across as the source is).
  double edge_gap_mm = 0.0005;
  double edge_angle_deg = 0.008;  ///< see edge_gap_mm
  /// The receiver the model is written for (receiver.hpp; empty: none, max_degree alone). A face
  /// it would not take is refitted from the original through the stack at the profile's fit
  /// degree and net cap (class A: degree 5, at most 32 per direction), with its edges matched
  /// as above and certified against the exact result; one only below its minimum degree
  /// (bicubic) is raised exactly. Faces written as planes, cylinders, ... (Face::elementary)
  /// conform as they are. The exact profile refits nothing: a face above degree 25 is refused.
  std::optional<ReceiverProfile> profile;

  /// Every bad field, each naming the field, its value and the rule broken; empty when valid.
  std::vector<std::string> problems() const;
  /// Throws clay::Error(InvalidArgument) listing problems(), if any.
  void validate() const;
};

/// What happened to the model.
struct CLAY_DEFORM_API ModelDeformationReport {
  brep::Counts counts;  ///< of the deformed model (the same as before, flattened)
  int faces_exact = 0, faces_refit = 0, faces_untouched = 0;
  /// With a receiver profile: its name, and the faces raised exactly to its minimum degree.
  std::string profile;
  int faces_elevated = 0;
  int edges_exact = 0, edges_refit = 0, edges_untouched = 0;
  /// Largest certified bound of a refitted face or edge (mm); 0 when everything was exact.
  double max_certified_bound_mm = 0;
  /// Largest gap between an edge and a face along its pcurve after the deformation, measured by
  /// brep::edge_gaps (mm).
  double max_edge_gap_mm = 0;
  /// Largest distance between an exact face or edge and the pointwise deformation of the
  /// original, from the compositions' own checks (mm).
  double max_deviation_mm = 0;
  double volume_before_mm3 = 0;  ///< brep::volume_mm3 of the solids
  double volume_after_mm3 = 0;
  int solids_reversed = 0;  ///< solids turned inside out by a mirroring stack, faces reversed
  /// Trimmed faces whose surface leaves a lattice though their trims do not: each composed on the
  /// box of its pcurves (surface::restricted, exact, the same (u, v); issue #39 item 7).
  int faces_restricted = 0;
  /// When every enabled step is a fold-free Bézier or B-spline lattice and every face was free to
  /// deform: bounds on the volume ratio det DF from the lattices' Jacobian coefficients
  /// (Sederberg–Parry §4), multiplied over the steps and widened to 1 (the FFD is the identity
  /// outside its lattice). volume_after / volume_before of each solid then lies within them
  /// (exactly for exact results; within the refits' bounds otherwise).
  bool volume_ratio_bounded = false;
  double volume_ratio_min = 1, volume_ratio_max = 1;
  /// How the faces meet along their shared edges (brep::edge_continuity), of the flattened model
  /// before and of the result, the same edges in the same order: an exact composition keeps each
  /// edge's continuity (a smooth map keeps tangency), a face-by-face refit can open a tangent
  /// edge, and this says where and by how much (issue #38).
  brep::ContinuityReport continuity_before, continuity_after;
  /// Converged, or Failed with the problems of the result; message = brief().
  Summary summary;
  /// One line: "42 faces: 30 exact, 0 refit, 12 untouched; 104 edges ...; edge gap 2e-12 mm;
  /// volume 44024.18 -> 52829.01 mm^3".
  std::string brief() const;
};

/// The deformed model and its report.
struct ModelDeformationResult {
  brep::Model model;
  ModelDeformationReport report;
};

/// `model` deformed by every enabled step of `stack` (see above). Throws clay::Error:
/// InvalidGeometry for an invalid model or stack (listing the problems), InvalidArgument for bad
/// options, the face's own composition error (OutOfDomain, DegreeLimit, InvalidArgument, naming
/// the face and its name) when it cannot be composed exactly and no refit is allowed,
/// ToleranceNotMet when the deformed model breaks an invariant (an edge gap above its tolerance,
/// listing them): a torn model is never returned.
CLAY_DEFORM_API ModelDeformationResult deform_model(const DeformationStack& stack,
                                                    const brep::Model& model,
                                                    const ModelDeformationOptions& options = {});

/// The frame of a lattice around `model` (around `faces` only, indices into
/// flattened(model).faces, when given), its edges along x, y and z: brep::control_box grown on
/// each side by `margin` times its extent along that axis, an axis thinner than a tenth of the
/// box's diagonal as if it were that thick (a flat part still gets a lattice with volume). Every
/// control point then lies
/// strictly inside, so every face composes exactly. Throws InvalidArgument for a margin outside
/// (0, 10] and as brep::control_box.
CLAY_DEFORM_API Frame frame_around(const brep::Model& model, double margin = 0.05,
                                   const std::vector<int>& faces = {});

}  // namespace clay::deform
