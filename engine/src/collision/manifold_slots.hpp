// Room for a pair function's working list of manifolds that is not written until used:
// a compound's list of 64 (some 10 KB) was otherwise filled with defaults on every call.
#pragma once

#include <cstddef>
#include <new>
#include <type_traits>

#include "collision/collide.hpp"

namespace spindle::detail {

template <std::size_t N>
class ManifoldSlots {
public:
    static_assert(std::is_trivially_destructible_v<Manifold>, "slots are never destroyed");

    ManifoldSlots() = default;
    ManifoldSlots(const ManifoldSlots&) = delete;
    ManifoldSlots& operator=(const ManifoldSlots&) = delete;

    // Slot i, which must have been filled (fill) before.
    Manifold& operator[](std::size_t i) { return data()[i]; }
    // Makes slot i a copy of m; slots are filled in order, from 0.
    void fill(std::size_t i, const Manifold& m) { new (m_bytes + i * sizeof(Manifold)) Manifold(m); }
    Manifold* data() { return std::launder(reinterpret_cast<Manifold*>(m_bytes)); }

private:
    alignas(Manifold) std::byte m_bytes[N * sizeof(Manifold)];
};

}  // namespace spindle::detail
