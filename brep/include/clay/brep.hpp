#pragma once
/// The B-rep module (Clayform::brep): models of bodies, shells and trimmed faces with shared
/// edges, names, colours and assemblies, as plain data (clay/brep/model.hpp), how their faces meet
/// along edges (clay/brep/continuity.hpp), the volume of their solids (clay/brep/volume.hpp) and
/// the types of their triangle meshes (clay/brep/mesh.hpp).
#include <clay/brep/continuity.hpp>
#include <clay/brep/mass_properties.hpp>
#include <clay/brep/mesh.hpp>
#include <clay/brep/model.hpp>
#include <clay/brep/volume.hpp>
