// Names of shape types, for error messages and reports.
#include <spindle/engine/shape.hpp>

namespace spindle {

const char* to_string(ShapeType type) noexcept {
    switch (type) {
        case ShapeType::Sphere: return "sphere";
        case ShapeType::Capsule: return "capsule";
        case ShapeType::Box: return "box";
        case ShapeType::ConvexHull: return "convex hull";
        case ShapeType::Plane: return "plane";
        case ShapeType::TriangleMesh: return "triangle mesh";
        case ShapeType::Compound: return "compound";
        case ShapeType::Count: break;
    }
    return "unknown shape";
}

}  // namespace spindle
