// A query's hold on the published query scene, and the first query of a space, which
// makes the scenes exist: until then no flip builds or keeps any (a space that never
// queries pays nothing for queries).
#pragma once

#include <memory>

namespace spindle {

class QueryScene;
struct World;

// Taken under the motion-state lock (briefly: two loads and an increment), released on
// destruction. Any thread. The space's first query builds the scenes, or has them built,
// before it returns (query_lease.cpp): from a thread that may make structural calls (no
// update runs) it builds them itself; a thread that holds the motion-state lock while
// another thread updates builds them while that thread waits for the lock at its flip;
// any other thread waits for the next flip, which builds the one it publishes. So the
// first query may wait for one update; every later one only for the lock.
class QueryLease {
public:
    explicit QueryLease(World& world);
    ~QueryLease();
    QueryLease(const QueryLease&) = delete;
    QueryLease& operator=(const QueryLease&) = delete;

    const QueryScene& scene() const noexcept { return *m_scene; }
    double alpha() const noexcept { return m_alpha; }

private:
    // Takes the published scene if there is one; the caller holds the lock.
    bool take_locked(World& world);

    std::shared_ptr<const QueryScene> m_scene;
    double m_alpha = 1;
};

}  // namespace spindle
