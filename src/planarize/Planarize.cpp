#include "planarize/Planarize.h"

#include "core/Error.h"
#include "planarize/AndersonPlanarizer.h"
#include "planarize/GaussNewtonPlanarizer.h"
#include "planarize/GuidedProjectionPlanarizer.h"
#include "planarize/ShapeUpPlanarizer.h"

namespace plano::planarize {

Method parseMethod(const std::string& text) {
  if (text == "shapeup") return Method::ShapeUp;
  if (text == "anderson") return Method::Anderson;
  if (text == "gauss-newton") return Method::GaussNewton;
  if (text == "guided") return Method::Guided;
  throwUsage("unknown planarization method '" + text + "' (use gauss-newton, guided, anderson or shapeup)");
}

const char* toString(Method method) {
  switch (method) {
    case Method::ShapeUp: return "shapeup";
    case Method::Anderson: return "anderson";
    case Method::GaussNewton: return "gauss-newton";
    case Method::Guided: return "guided";
  }
  return "unknown";
}

const char* toString(Status status) {
  switch (status) {
    case Status::Converged: return "converged";
    case Status::IterationLimit: return "iteration_limit";
    case Status::Stalled: return "stalled";
  }
  return "unknown";
}

Info planarize(const FaceList& faces, Positions& vertices, const Settings& settings, compute::Backend& backend) {
  const Positions input = vertices;
  switch (settings.method) {
    case Method::ShapeUp: return ShapeUpPlanarizer(faces, input, settings, backend).solve(vertices);
    case Method::Anderson: return AndersonPlanarizer(faces, input, settings, backend).solve(vertices);
    case Method::GaussNewton: return GaussNewtonPlanarizer(faces, input, settings, backend).solve(vertices);
    case Method::Guided: return GuidedProjectionPlanarizer(faces, input, settings, backend).solve(vertices);
  }
  throwUsage("planarize: unknown method");
}

}  // namespace plano::planarize
