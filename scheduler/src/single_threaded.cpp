// SingleThreadedJobSystem: chunks in order on the caller.
#include <spindle/scheduler/single_threaded.hpp>

#include <utility>
#include <vector>

namespace spindle {

void SingleThreadedJobSystem::parallel_for(const char*, std::uint32_t begin, std::uint32_t end, std::uint32_t grain,
                                           RangeFn fn) {
    if (grain == 0) grain = 1;
    for (std::uint32_t lo = begin; lo < end;) {
        const std::uint32_t hi = end - lo > grain ? lo + grain : end;  // no overflow near UINT32_MAX
        fn(lo, hi, 0);
        lo = hi;
    }
}

void SingleThreadedJobSystem::run_phases(const char*, std::span<const Phase> phases, PhaseFn fn) {
    for (std::uint32_t p = 0; p < phases.size(); ++p) {
        if (phases[p].count > 0) fn(p, 0, phases[p].count, 0);
    }
}

void SingleThreadedJobSystem::run_graph(StageGraph& graph) {
    std::vector<std::uint32_t> waiting(graph.m_nodes.size());
    std::vector<std::uint32_t> ready;
    for (std::uint32_t i = 0; i < graph.m_nodes.size(); ++i) {
        waiting[i] = graph.m_nodes[i].prerequisites;
        if (waiting[i] == 0) ready.push_back(i);
    }
    std::exception_ptr error;
    for (std::size_t k = 0; k < ready.size(); ++k) {  // ready grows as nodes finish
        StageGraph::Node& node = graph.m_nodes[ready[k]];
        try {
            node.fn(0);
        } catch (...) {
            if (!error) error = std::current_exception();
        }
        for (std::uint32_t d : node.dependents) {
            if (--waiting[d] == 0) ready.push_back(d);
        }
    }
    if (error) std::rethrow_exception(error);
}

void SingleThreadedJobSystem::keep_error(JobGroup& group, std::exception_ptr error) {
    std::scoped_lock guard(group.m_error_lock);
    if (!group.m_error) group.m_error = std::move(error);
}

void SingleThreadedJobSystem::wait(JobGroup& group) {
    std::exception_ptr error;
    {
        std::scoped_lock guard(group.m_error_lock);
        error = std::exchange(group.m_error, nullptr);
    }
    if (error) std::rethrow_exception(error);
}

}  // namespace spindle
