// Triangle meshes for tests: a square grid about the origin, flat on y = 0 or at given
// heights, two triangles a cell, their fronts up. Suites that need one add this folder to
// their include path.
#pragma once

#include <cstdint>
#include <vector>

#include <spindle/engine/shape.hpp>

namespace spindle::test {

// cells x cells squares of side `cell`, centred on the origin, each vertex at the height
// height(x, z) gives.
template <class Height>
Shape height_grid_mesh(int cells, Real cell, Height height) {
    std::vector<Vec3> vertices;
    std::vector<std::uint32_t> indices;
    for (int i = 0; i <= cells; ++i) {
        for (int k = 0; k <= cells; ++k) {
            const Real x = (i - cells / 2) * cell, z = (k - cells / 2) * cell;
            vertices.emplace_back(x, height(x, z), z);
        }
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

// cells x cells squares of side `cell` on y = 0, centred on the origin.
inline Shape flat_grid_mesh(int cells, Real cell) {
    return height_grid_mesh(cells, cell, [](Real, Real) { return Real(0); });
}

}  // namespace spindle::test
