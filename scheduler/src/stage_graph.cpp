// StageGraph: building the graph (nodes, dependencies), and WorkStealingJobSystem::run_graph,
// which submits each node once its prerequisites finished.
#include <spindle/platform/error.hpp>
#include <spindle/scheduler/job_system.hpp>
#include <spindle/scheduler/work_stealing.hpp>

#include <atomic>
#include <cstdint>

namespace spindle {

void WorkStealingJobSystem::run_graph(StageGraph& graph) {
    JobGroup group;
    struct Launch {
        WorkStealingJobSystem* system;
        StageGraph* graph;
        JobGroup* group;
        void start(std::uint32_t node) const {
            StageGraph::Node& n = graph->m_nodes[node];
            const Launch self = *this;
            system->submit(*group, n.name, [self, node](unsigned worker) {
                StageGraph::Node& me = self.graph->m_nodes[node];
                me.fn(worker);
                // Each dependent waits for `prerequisites` nodes; the last one to finish starts it.
                for (std::uint32_t d : me.dependents) {
                    if (self.graph->m_nodes[d].waiting.fetch_sub(1, std::memory_order_acq_rel) == 1) self.start(d);
                }
            });
        }
    };
    const Launch launch{this, &graph, &group};
    for (StageGraph::Node& n : graph.m_nodes) n.waiting.store(n.prerequisites, std::memory_order_relaxed);
    for (std::uint32_t i = 0; i < graph.m_nodes.size(); ++i) {
        if (graph.m_nodes[i].prerequisites == 0) launch.start(i);
    }
    wait(group);
}

std::uint32_t StageGraph::add(const char* name, Fn fn) {
    m_nodes.emplace_back(name, fn);
    return static_cast<std::uint32_t>(m_nodes.size() - 1);
}

void StageGraph::depends_on(std::uint32_t node, std::uint32_t prerequisite) {
    if (node >= m_nodes.size() || prerequisite >= m_nodes.size() || node == prerequisite) {
        throw Error("StageGraph::depends_on: bad node index");
    }
    m_nodes[prerequisite].dependents.push_back(node);
    m_nodes[node].prerequisites += 1;
}

}  // namespace spindle
