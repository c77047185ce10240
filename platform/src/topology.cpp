// Topology: read packages, cores and PUs from hwloc into plain vectors.
#include <spindle/platform/error.hpp>
#include <spindle/platform/topology.hpp>

#include <sstream>

#include "hwloc_util.hpp"

namespace spindle {
namespace detail {

hwloc_topology_t system_topology() {
    static HwlocTopology* topology = [] {
        auto* t = new HwlocTopology();  // lives for the process: binding may happen at exit
        if (hwloc_topology_load(t->get()) != 0) throw Error("hwloc: cannot load this machine's topology");
        return t;
    }();
    return topology->get();
}

}  // namespace detail

namespace {

void read_topology(hwloc_topology_t t, std::vector<PuInfo>& pus, std::vector<CoreInfo>& cores, unsigned& packages) {
    const int n = hwloc_get_nbobjs_by_type(t, HWLOC_OBJ_PU);
    const int n_packages = hwloc_get_nbobjs_by_type(t, HWLOC_OBJ_PACKAGE);
    packages = n_packages > 0 ? static_cast<unsigned>(n_packages) : 1u;
    pus.clear();
    cores.clear();
    for (int i = 0; i < n; ++i) {
        hwloc_obj_t pu = hwloc_get_obj_by_type(t, HWLOC_OBJ_PU, static_cast<unsigned>(i));
        hwloc_obj_t core = hwloc_get_ancestor_obj_by_type(t, HWLOC_OBJ_CORE, pu);
        hwloc_obj_t package = hwloc_get_ancestor_obj_by_type(t, HWLOC_OBJ_PACKAGE, pu);
        PuInfo info;
        info.logical = static_cast<unsigned>(i);
        info.os_index = pu->os_index;
        info.package = package ? package->logical_index : 0u;
        // A machine without a core level: every PU is its own core.
        const unsigned core_key = core ? core->logical_index : static_cast<unsigned>(i);
        if (cores.empty() || cores.back().logical != core_key) {
            // hwloc lists PUs in logical order, so a core's PUs are contiguous.
            cores.push_back(CoreInfo{core_key, info.package, {}});
        }
        info.core = static_cast<unsigned>(cores.size() - 1);
        cores.back().logical = info.core;
        cores.back().pus.push_back(info.logical);
        pus.push_back(info);
    }
}

}  // namespace

Topology Topology::from_system() {
    Topology result;
    read_topology(detail::system_topology(), result.m_pus, result.m_cores, result.m_packages);
    result.m_description = "this machine";
    result.m_real = true;
    if (result.m_pus.empty()) throw Error("hwloc: this machine reports no hardware threads");
    return result;
}

Topology Topology::from_synthetic(std::string_view description) {
    detail::HwlocTopology t;
    const std::string text(description);
    if (hwloc_topology_set_synthetic(t.get(), text.c_str()) != 0 || hwloc_topology_load(t.get()) != 0) {
        throw Error("hwloc rejected the synthetic topology \"" + text + "\" (expected e.g. \"package:1 core:3 pu:2\")");
    }
    Topology result;
    read_topology(t.get(), result.m_pus, result.m_cores, result.m_packages);
    result.m_description = text;
    result.m_real = false;
    if (result.m_pus.empty()) throw Error("synthetic topology \"" + text + "\" has no hardware threads");
    return result;
}

std::string Topology::summary() const {
    std::ostringstream out;
    out << m_description << ": " << m_packages << (m_packages == 1 ? " package, " : " packages, ") << m_cores.size()
        << (m_cores.size() == 1 ? " core, " : " cores, ") << m_pus.size()
        << (m_pus.size() == 1 ? " hardware thread" : " hardware threads") << '\n';
    for (const CoreInfo& core : m_cores) {
        out << "  package " << core.package << " core " << core.logical << ": PU";
        for (unsigned pu : core.pus) out << ' ' << pu << " (os " << m_pus[pu].os_index << ')';
        out << '\n';
    }
    return out.str();
}

}  // namespace spindle
