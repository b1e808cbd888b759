#pragma once
/// How the faces of a model meet along their shared edges: the largest gap, the largest angle
/// between their tangent planes and the largest jump of curvature across each edge (issue #38,
/// item 4; docs/brep.md "Continuity"). The figures a class-A check reads: gap <= 0.01 mm (fillets
/// 0.001 mm), tangent-plane angle <= 0.1 deg (fillets about 0.016 deg), curvature matched where
/// the source was G2.
///
/// Sampled, not certified: each edge at `samples_per_span` points in every knot span of its curve
/// and of both pcurves (and at both ends). At each sample t both faces are evaluated at their own
/// pcurve's (u, v) (same parameter, model.hpp), so nothing is projected:
/// - gap: |S_a(p_a(t)) - S_b(p_b(t))|;
/// - tangent-plane angle: the angle between the faces' outward normals (S_u x S_v, negated for a
///   reversed face): 0 where they join smoothly in a consistently oriented shell, 90 deg at a
///   box's edge;
/// - curvature across the edge: each face's normal curvature II(w) / I(w) in the direction w
///   across the edge (w = n x T, T the edge's tangent, both from the face's own derivatives; The
///   NURBS Book does not give it, do Carmo §3-2 does), with respect to its outward normal. The
///   jump is |k_a - k_b|, and relative to max(|k_a|, |k_b|, curvature_floor): a plane meeting a
///   cylinder tangentially jumps by 1 (G1, not G2); two pieces of one smooth surface by 0.
#include <clay/brep/export.hpp>
#include <clay/brep/model.hpp>

#include <string>
#include <vector>

namespace clay::brep {

/// Settings of edge_continuity().
struct CLAY_BREP_API ContinuityOptions {
  int samples_per_span = 16;      ///< >= 1: samples inside each knot span of the edge's curves
  double curvature_floor = 1e-6;  ///< 1/mm, > 0: curvatures below it count as flat (radius 1 km)
                                  ///< when the jump is made relative

  /// Every bad field, each naming the field, its value and the rule broken; empty when valid.
  std::vector<std::string> problems() const;
  /// Throws clay::Error(InvalidArgument) listing problems(), if any.
  void validate() const;
};

/// How the two faces using one edge meet, at its worst samples.
struct EdgeContinuity {
  int edge = -1;                       ///< index into Model::edges
  int face_a = -1, face_b = -1;        ///< the faces of its two uses (the same face along a seam)
  double gap_mm = 0;                   ///< largest distance between the faces at one t
  double angle_deg = 0;                ///< largest angle between their outward normals, in [0, 180]
  double curvature_jump = 0;           ///< largest |k_a - k_b| across the edge (1/mm)
  double relative_curvature_jump = 0;  ///< largest |k_a - k_b| / max(|k_a|, |k_b|, floor)
  double t_gap = 0, t_angle = 0, t_curvature = 0;  ///< edge parameters where each is largest
  int samples = 0;                                 ///< samples taken along the edge
};

/// The continuity of every edge two faces (or one face, twice: a seam) use, in edge order.
struct CLAY_BREP_API ContinuityReport {
  std::vector<EdgeContinuity> edges;
  int boundary_edges = 0;      ///< edges used once (a sheet's border): nothing to compare
  int degenerate_edges = 0;    ///< poles: no direction across them
  int non_manifold_edges = 0;  ///< edges used three times or more: which two faces meet there is
                               ///< not defined, so they are counted, not measured
  double max_gap_mm = 0, max_angle_deg = 0, max_relative_curvature_jump = 0;

  /// One line: "12 shared edges: gap <= 1.2e-07 mm, angle <= 90 deg, relative curvature jump
  /// <= 1 (3 boundary, 2 degenerate edges)", and the non-manifold edges when there are any.
  std::string brief() const;
};

/// Measures how the faces meet along every edge used twice. Throws clay::Error: InvalidArgument
/// for bad options; InvalidGeometry when a face's surface, an edge's curve or a pcurve is invalid
/// or an index is out of range (problems(model) names them).
CLAY_BREP_API ContinuityReport edge_continuity(const Model& model,
                                               const ContinuityOptions& options = {});

}  // namespace clay::brep
