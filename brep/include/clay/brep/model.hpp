#pragma once
/// Model — a boundary representation (B-rep) as plain data, free of OpenCASCADE (issue #20).
///
/// model → bodies (solid, shell or sheet) → shells → faces. A face is a NURBS surface bounded
/// by loops of coedges; a coedge is one use of an edge by a face, with the edge's curve in the
/// face's (u, v) plane (its pcurve). Edges and vertices are shared: two faces that meet along an
/// edge both refer to the same Edge by index, so a deformation that maps the edge once keeps the
/// faces joined. Everything is held by value in the Model's arrays and referred to by index, so a
/// model copies, compares and serializes as data.
///
/// Conventions (checked by problems()):
/// - Same parameter: a coedge's pcurve is parametrized like its edge, so for t in [t0, t1]
///   surface(pcurve(t)) lies within the edge's tolerance of curve(t). Exact composition F∘S keeps
///   (u, v), so a deformed face keeps its pcurves bit for bit while its edges become F∘C.
/// - A pcurve is a surface::BSplineCurve in the plane z = 0: control point (u, v, 0). One curve
///   type serves 2D and 3D, so no algorithm exists twice.
/// - Loops run with the face on their left in the surface's (u, v) plane: the outer loop
///   counter-clockwise, inner loops (holes) clockwise. `Face::reversed` says the face's outward
///   side is -(S_u × S_v) instead of S_u × S_v; it does not change the loops.
/// - A coedge's direction around its face's outward normal is `same_sense` when the face is not
///   reversed, and the opposite when it is. In a consistently oriented shell the two coedges of an
///   interior edge run in opposite directions; a seam is one edge used twice by one face.
/// - A degenerate edge (a pole of a sphere or cone) has no 3D curve: it stands at its vertex, and
///   its pcurve runs along the collapsed side of the (u, v) domain.
/// - Units are millimetres, as everywhere in Clayform; colours are sRGB components in [0, 1].
#include <clay/brep/export.hpp>
#include <clay/surface/bspline_curve.hpp>
#include <clay/surface/bspline_surface.hpp>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace clay::brep {

/// An sRGB colour, each component in [0, 1] (STEP's colour_rgb, IGES 314).
struct Colour {
  double r = 0, g = 0, b = 0;
  friend bool operator==(const Colour&, const Colour&) = default;
};

/// A point where edges end, and how far from it their ends may lie.
struct Vertex {
  Eigen::Vector3d point = Eigen::Vector3d::Zero();
  double tolerance_mm = 1e-7;
};

/// A 3D curve piece shared by the faces that meet along it.
struct Edge {
  surface::BSplineCurve curve;  ///< 3D; ignored (may be empty) when `degenerate`
  double t0 = 0, t1 = 1;        ///< the piece of `curve` used: t0 < t1, inside its domain
  double tolerance_mm = 1e-7;   ///< how far its faces (along their pcurves) may be from it
  int start = -1, end = -1;     ///< vertex indices: curve(t0) at start, curve(t1) at end
  bool degenerate = false;      ///< collapsed to its start vertex (== end): a pole
};

/// One use of an edge by a face: the edge's curve in the face's (u, v) plane.
struct Coedge {
  int edge = -1;                 ///< index into Model::edges
  bool same_sense = true;        ///< the loop runs along the edge from t0 to t1 (else back)
  surface::BSplineCurve pcurve;  ///< points (u, v, 0), parametrized like the edge on [t0, t1]
};

/// A closed chain of coedges: each one ends at the vertex where the next one starts.
struct Loop {
  std::vector<Coedge> coedges;
};

/// The kinds of analytic surface a face can be read as and written back as.
enum class ElementaryKind { Plane, Cylinder, Cone, Sphere, Torus };

/// An analytic surface in OpenCASCADE's (and STEP's) parametrization, in a frame whose axes are
/// orthonormal; y is ±(z × x), so a left-handed frame is kept as it came (read_model gives a
/// plane's frame right-handed: its parameters depend on x and y only). With
/// e(u) = cos u x + sin u y:
/// - plane:    origin + u x + v y;
/// - cylinder: origin + radius e(u) + v z;
/// - cone:     origin + (radius + v sin semi_angle) e(u) + v cos semi_angle z;
/// - sphere:   origin + radius (cos v e(u) + sin v z);
/// - torus:    origin + (radius + minor_radius cos v) e(u) + minor_radius sin v z.
struct Elementary {
  ElementaryKind kind = ElementaryKind::Plane;
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();
  Eigen::Vector3d x_axis = Eigen::Vector3d::UnitX(), y_axis = Eigen::Vector3d::UnitY(),
                  z_axis = Eigen::Vector3d::UnitZ();
  double radius = 0;        ///< cylinder, cone (at v = 0), sphere; a torus's major radius
  double minor_radius = 0;  ///< torus
  double semi_angle = 0;    ///< cone, in radians, in (-pi/2, pi/2) and not 0
  friend bool operator==(const Elementary&, const Elementary&) = default;
};

/// The point of `e` at (u, v), by the formulas of Elementary.
CLAY_BREP_API Eigen::Vector3d point(const Elementary& e, double u, double v);

/// The distance from `p` to the whole (unbounded) surface `e`, in closed form.
CLAY_BREP_API double distance(const Elementary& e, const Eigen::Vector3d& p);

/// A bounded piece of a NURBS surface.
struct Face {
  surface::BSplineSurface surface;
  /// The analytic surface `surface` represents exactly, when the face was read as one: kept by
  /// every operation that leaves the face's geometry as it is (flattened, an untouched face of
  /// deform_model), dropped by any that changes it. For a plane, `surface` has the plane's own
  /// parameters, so the pcurves serve both and write_model writes the face as a plane.
  std::optional<Elementary> elementary;
  bool reversed = false;    ///< outward side is -(S_u × S_v)
  std::vector<Loop> loops;  ///< loops[0] the outer loop, the others holes; empty: untrimmed
  std::string name;         ///< "" when unnamed
  std::optional<Colour> colour;
};

/// Connected faces. Closed when every edge of its faces is used twice (or is a pole).
struct Shell {
  std::vector<int> faces;  ///< indices into Model::faces
};

/// What a body is: a solid (closed shells: the first the outside, the others voids), one or more
/// connected shells of faces (open or closed), loose faces, or a wire body: free edges (curves no
/// face uses: a wireframe, a package drawing's lines, style curves sent beside their surfaces).
enum class BodyKind { Solid, Shell, Sheet, Wire };

/// A body: its shells (a wire body: its edges instead), name and colour.
struct Body {
  BodyKind kind = BodyKind::Solid;
  std::vector<Shell> shells;  ///< empty for a wire body
  /// A wire body's edges, indices into Model::edges, in the order they were read (chains share
  /// vertices); no face uses them. Empty for the other kinds.
  std::vector<int> edges;
  std::string name;
  std::optional<Colour> colour;
};

struct Part;

/// A placed copy of a part in an assembly: world = placement * part coordinates.
struct Instance {
  int part = -1;  ///< index into Model::parts
  Eigen::Isometry3d placement = Eigen::Isometry3d::Identity();
  std::string name;  ///< the instance's own name ("" when unnamed)
};

/// A node of the assembly tree: its own bodies and placed sub-parts (STEP's product, XCAF's
/// shape label). A part used twice is stored once and instanced twice.
struct Part {
  std::string name;
  std::vector<int> bodies;           ///< indices into Model::bodies
  std::vector<Instance> components;  ///< sub-assemblies and parts, placed
  std::optional<Colour> colour;
};

/// A whole model. Without an assembly (parts and roots empty), every body stands in world
/// coordinates.
struct CLAY_BREP_API Model {
  std::vector<Vertex> vertices;
  std::vector<Edge> edges;
  std::vector<Face> faces;
  std::vector<Body> bodies;
  std::vector<Part> parts;
  std::vector<Instance> roots;  ///< the top of the assembly tree

  /// True when the model has an assembly tree (roots not empty).
  bool is_assembly() const noexcept { return !roots.empty(); }
};

/// How many of each thing a model holds (clayform info, import and deformation reports).
struct Counts {
  int bodies = 0, solids = 0, shells = 0, faces = 0, trimmed_faces = 0, loops = 0, inner_loops = 0,
      coedges = 0, edges = 0, degenerate_edges = 0, vertices = 0, parts = 0, instances = 0;
  int wires = 0, wire_edges = 0;  ///< wire bodies, and the edges they hold (among `edges`)
  friend bool operator==(const Counts&, const Counts&) = default;
};

/// The counts of `model`. A face is trimmed when it has loops.
CLAY_BREP_API Counts counts(const Model& model);

/// Where a face and an edge are farthest apart along one coedge.
struct EdgeGap {
  int face = -1, loop = -1,
      coedge = -1;  ///< the coedge: model.faces[face].loops[loop].coedges[coedge]
  int edge = -1;
  double t = 0;       ///< the edge parameter of the largest gap
  double gap_mm = 0;  ///< |surface(pcurve(t)) - curve(t)| (the vertex for a pole)
};

/// The largest gap between each coedge's face (along its pcurve) and its edge, sampled at
/// `samples_per_span` points in every knot span of the pcurve and of the edge curve inside
/// [t0, t1] (and at both ends), one entry per coedge in face, loop, coedge order. Evaluates the
/// surface and the curves directly: independent of how the model was built. Throws
/// InvalidGeometry when a coedge's indices or curves are invalid (see problems()).
CLAY_BREP_API std::vector<EdgeGap> edge_gaps(const Model& model, int samples_per_span = 16);

/// The signed area in (u, v) of loop `loop` of face `face`: the polygon through 8 samples per
/// knot span of each coedge's pcurve, in loop order; positive when it runs counter-clockwise
/// (an outer loop), negative for a hole. Throws InvalidArgument for indices out of range,
/// InvalidGeometry when a coedge's data is invalid (see problems()).
CLAY_BREP_API double loop_area(const Model& model, int face, int loop);

/// Every invariant the model breaks, in words, each naming the body, face, loop, coedge, edge or
/// vertex. Empty when valid:
/// - indices in range; surfaces, curves and pcurves valid; pcurves in the plane z = 0 and inside
///   the surface's domain; edge ranges inside their curve's domain and along the pcurve's;
///   tolerances finite and >= 0; colours in [0, 1];
/// - an edge's ends lie on its vertices (within both tolerances);
/// - every loop is closed: each coedge ends at the vertex where the next one starts;
/// - the face meets each edge along its pcurve within the edge's tolerance (edge_gaps);
/// - the outer loop runs counter-clockwise in (u, v) and holes clockwise;
/// - in a shell, an edge is used by at most two coedges, and two uses run in opposite directions
///   (a consistent orientation); every shell of a solid is closed, and no edge is left dangling
///   (unused by any face and by any wire body);
/// - a wire body holds edges and no shells; its edges are not degenerate, and no face and no other
///   wire body uses them;
/// - the assembly tree refers to existing parts and bodies and has no cycle.
CLAY_BREP_API std::vector<std::string> problems(const Model& model);

/// The model without its assembly: every placed instance of a body becomes a body of its own in
/// world coordinates (control points, edge curves and vertices moved by the placement, pcurves
/// unchanged), named after the body or else its part, coloured by the body or else the nearest
/// coloured part above it. A model without an assembly comes back as it is. A deformation of
/// space moves each instance differently, so it deforms the flattened model. Throws
/// clay::Error(InvalidGeometry) when the assembly tree refers to missing parts or bodies or has a
/// cycle.
CLAY_BREP_API Model flattened(const Model& model);

/// An axis-aligned box (mm): lo <= hi componentwise.
struct Box {
  Eigen::Vector3d lo = Eigen::Vector3d::Zero(), hi = Eigen::Vector3d::Zero();
};

/// The box of the control points of the faces and wire bodies' edges of flattened(model) (of
/// `faces` only, indices into flattened(model).faces, when given): it contains those faces and
/// their whole untrimmed surfaces, and the curves (convex hull property, weights positive), which
/// is what a lattice must contain for an exact composition. Throws InvalidArgument for a model
/// with neither faces nor wire edges or a face index out of range, InvalidGeometry as flattened.
CLAY_BREP_API Box control_box(const Model& model, const std::vector<int>& faces = {});

/// Throws clay::Error(InvalidGeometry) listing problems(model) when there are any.
CLAY_BREP_API void validate(const Model& model);

/// The name of an elementary kind: "plane", "cylinder", "cone", "sphere", "torus".
CLAY_BREP_API std::string_view to_string(ElementaryKind kind) noexcept;

/// The name of a body kind: "solid", "shell", "sheet", "wire".
CLAY_BREP_API std::string_view to_string(BodyKind kind) noexcept;

}  // namespace clay::brep
