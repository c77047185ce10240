// Pinning and naming the calling thread, through hwloc on the real machine.
#include <spindle/platform/error.hpp>
#include <spindle/platform/thread.hpp>

#include <pthread.h>
#include <sched.h>

#include <string>

#include "hwloc_util.hpp"

namespace spindle {

void pin_current_thread(unsigned os_pu) { pin_current_thread(std::span<const unsigned>(&os_pu, 1)); }

void pin_current_thread(std::span<const unsigned> os_pus) {
    if (os_pus.empty()) throw Error("pin_current_thread: no hardware thread given");
    hwloc_topology_t t = detail::system_topology();
    hwloc_const_cpuset_t allowed = hwloc_topology_get_allowed_cpuset(t);
    detail::HwlocBitmap set;
    for (unsigned pu : os_pus) {
        if (!hwloc_bitmap_isset(allowed, pu)) {
            throw Error("pin_current_thread: hardware thread (PU os index) " + std::to_string(pu) +
                        " does not exist or is not available to this process");
        }
        hwloc_bitmap_set(set.get(), pu);
    }
    if (hwloc_set_cpubind(t, set.get(), HWLOC_CPUBIND_THREAD) != 0) {
        throw Error("pin_current_thread: the OS refused to bind to PU " + std::to_string(os_pus.front()));
    }
}

void unpin_current_thread() {
    hwloc_topology_t t = detail::system_topology();
    if (hwloc_set_cpubind(t, hwloc_topology_get_allowed_cpuset(t), HWLOC_CPUBIND_THREAD) != 0) {
        throw Error("unpin_current_thread: the OS refused to widen the binding");
    }
}

std::vector<unsigned> current_binding() {
    detail::HwlocBitmap set;
    if (hwloc_get_cpubind(detail::system_topology(), set.get(), HWLOC_CPUBIND_THREAD) != 0) {
        throw Error("current_binding: the OS did not report this thread's binding");
    }
    std::vector<unsigned> result;
    for (int i = hwloc_bitmap_first(set.get()); i != -1; i = hwloc_bitmap_next(set.get(), i)) {
        result.push_back(static_cast<unsigned>(i));
    }
    return result;
}

int current_cpu() noexcept { return sched_getcpu(); }

void set_current_thread_name(std::string_view name) {
    const std::string truncated(name.substr(0, 15));
    pthread_setname_np(pthread_self(), truncated.c_str());
}

std::string current_thread_name() {
    char buffer[16] = {};
    pthread_getname_np(pthread_self(), buffer, sizeof buffer);
    return buffer;
}

}  // namespace spindle
