// The hardware threads of a machine, read through hwloc: from the real machine, or
// from a hwloc synthetic description ("package:1 core:3 pu:2") so that tests can model
// any machine. A Topology is a plain value: hwloc is not kept open.
#pragma once

#include <string>
#include <string_view>
#include <vector>

namespace spindle {

struct PuInfo {
    unsigned logical = 0;   // position among all PUs, 0..n-1 (a layout's "hardware thread")
    unsigned os_index = 0;  // what the OS calls it; what pinning takes
    unsigned core = 0;      // logical index of its core
    unsigned package = 0;   // logical index of its package
};

struct CoreInfo {
    unsigned logical = 0;
    unsigned package = 0;
    std::vector<unsigned> pus;  // logical PU indices, ascending
};

class Topology {
public:
    // The machine this process runs on (only the PUs it is allowed to use).
    static Topology from_system();
    // A modelled machine; throws spindle::Error when hwloc rejects the description.
    static Topology from_synthetic(std::string_view description);

    const std::vector<PuInfo>& pus() const noexcept { return m_pus; }
    const std::vector<CoreInfo>& cores() const noexcept { return m_cores; }
    unsigned package_count() const noexcept { return m_packages; }
    // "package:1 core:3 pu:2" for a synthetic model, "this machine" for the real one.
    const std::string& description() const noexcept { return m_description; }
    bool is_real() const noexcept { return m_real; }

    // One line per package/core/PU; what `spindle layout` prints for a machine.
    std::string summary() const;

private:
    std::vector<PuInfo> m_pus;
    std::vector<CoreInfo> m_cores;
    unsigned m_packages = 0;
    std::string m_description;
    bool m_real = false;
};

}  // namespace spindle
