#pragma once
/// The OpenCASCADE library (Clayform::occt): STEP/IGES/glTF exchange of surfaces
/// (clay/occt/surface_exchange.hpp) and of whole models with meshing and BRepCheck validity
/// (clay/occt/model_exchange.hpp), and the OCCT-backed fills (clay/occt/fill.hpp). No OCCT type
/// appears in these headers.
#include <clay/occt/fill.hpp>
#include <clay/occt/model_exchange.hpp>
#include <clay/occt/surface_exchange.hpp>
