#pragma once
// A recipe's stroke replaced by the curve fitted to it, written as a "bspline" curve: what the
// tests that drag a style's target control point by control point start from (the tank's "spine").
#include <clay/surface/bspline_curve.hpp>

#include <nlohmann/json.hpp>

#include <string>

/// `doc` with stroke `name` replaced by curve `name` {"bspline": degree, knots, points of
/// `fitted`}.
inline nlohmann::json with_bspline_curve(nlohmann::json doc, const std::string& name,
                                         const clay::surface::BSplineCurve& fitted) {
  nlohmann::json points = nlohmann::json::array();
  for (Eigen::Index k = 0; k < fitted.points.rows(); ++k)
    points.push_back({fitted.points(k, 0), fitted.points(k, 1), fitted.points(k, 2)});
  doc["strokes"].erase(name);
  doc["curves"][name] = {
      {"bspline",
       {{"degree", fitted.basis.degree}, {"knots", fitted.basis.knots}, {"points", points}}}};
  return doc;
}
