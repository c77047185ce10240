// A flat triangle mesh for tests: a square grid on y = 0 about the origin, two triangles
// a cell, their fronts up. Suites that need one add this folder to their include path.
#pragma once

#include <cstdint>
#include <vector>

#include <spindle/engine/shape.hpp>

namespace spindle::test {

// cells x cells squares of side `cell`, centred on the origin.
inline Shape flat_grid_mesh(int cells, Real cell) {
    std::vector<Vec3> vertices;
    std::vector<std::uint32_t> indices;
    for (int i = 0; i <= cells; ++i) {
        for (int k = 0; k <= cells; ++k) vertices.emplace_back((i - cells / 2) * cell, 0, (k - cells / 2) * cell);
    }
    auto at = [cells](int i, int k) { return static_cast<std::uint32_t>(i * (cells + 1) + k); };
    for (int i = 0; i < cells; ++i) {
        for (int k = 0; k < cells; ++k) {
            // Counter-clockwise seen from above: the front faces +y.
            for (std::uint32_t v : {at(i, k), at(i, k + 1), at(i + 1, k), at(i + 1, k), at(i, k + 1), at(i + 1, k + 1)})
                indices.push_back(v);
        }
    }
    return Shape::triangle_mesh(vertices, indices);
}

}  // namespace spindle::test
