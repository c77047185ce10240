// RAII for an hwloc topology, shared by topology.cpp and thread.cpp.
#pragma once

#include <hwloc.h>

namespace spindle::detail {

class HwlocTopology {
public:
    HwlocTopology() { hwloc_topology_init(&m_topology); }
    ~HwlocTopology() { hwloc_topology_destroy(m_topology); }
    HwlocTopology(const HwlocTopology&) = delete;
    HwlocTopology& operator=(const HwlocTopology&) = delete;
    hwloc_topology_t get() const noexcept { return m_topology; }

private:
    hwloc_topology_t m_topology{};
};

class HwlocBitmap {
public:
    HwlocBitmap() : m_bitmap(hwloc_bitmap_alloc()) {}
    ~HwlocBitmap() { hwloc_bitmap_free(m_bitmap); }
    HwlocBitmap(const HwlocBitmap&) = delete;
    HwlocBitmap& operator=(const HwlocBitmap&) = delete;
    hwloc_bitmap_t get() const noexcept { return m_bitmap; }

private:
    hwloc_bitmap_t m_bitmap;
};

// The loaded topology of this machine, created once; hwloc allows concurrent
// read-only use (including binding calls) from many threads.
hwloc_topology_t system_topology();

}  // namespace spindle::detail
