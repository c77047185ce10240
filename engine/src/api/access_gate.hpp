// AccessGate: who may change (or read the live state of) a Space right now. The
// structural calls (create_body, destroy_body, joints, settings, the internal_*
// accessors) and update() each pass it, so that a structural call from another thread
// while an update runs gets a spindle::Error instead of corrupting memory (issue 15), and
// while an AsyncRunner's loop owns the space, every call from another thread does (it
// would succeed or fail by timing otherwise: post it to the loop instead).
#pragma once

#include <atomic>
#include <mutex>
#include <string>
#include <thread>

#include <spindle/platform/error.hpp>

namespace spindle {

class AccessGate {
public:
    // A structural call or an internal read, for its scope. Calls on one thread nest;
    // calls from several threads outside updates take turns.
    class Structure {
    public:
        Structure(AccessGate& gate, const char* what);
        // The same without waiting or throwing, for a caller that has something else to
        // do when the space is busy (a first scene query): owns() says whether it may go on.
        Structure(AccessGate& gate, std::try_to_lock_t);
        ~Structure();
        Structure(const Structure&) = delete;
        Structure& operator=(const Structure&) = delete;

        bool owns() const noexcept { return m_owns; }

    private:
        AccessGate& m_gate;
        bool m_took = false;
        bool m_owns = true;
    };

    // An update (or flush), for its scope: waits for a structural call in progress on
    // another thread (they are short); throws if another thread's update runs.
    class Update {
    public:
        Update(AccessGate& gate, const char* what);
        ~Update();
        Update(const Update&) = delete;
        Update& operator=(const Update&) = delete;

    private:
        AccessGate& m_gate;
        bool m_took = false;
    };

    // An AsyncRunner's loop thread claims the space while it runs (none: released).
    void claim(std::thread::id owner) noexcept { m_claimed_by.store(owner, std::memory_order_release); }

private:
    enum State : int { kFree = 0, kStructure = 1, kUpdate = 2 };
    void check_claim(const char* what) const;
    bool claimed_by_other() const noexcept;

    std::mutex m_structure;  // structural calls from several threads take turns
    std::atomic<int> m_state{kFree};
    std::atomic<std::thread::id> m_holder{};  // the thread in a structural call or update
    std::atomic<std::thread::id> m_claimed_by{};
};

inline bool AccessGate::claimed_by_other() const noexcept {
    const std::thread::id claimed = m_claimed_by.load(std::memory_order_acquire);
    return claimed != std::thread::id{} && claimed != std::this_thread::get_id();
}

inline void AccessGate::check_claim(const char* what) const {
    if (claimed_by_other()) {
        throw Error(std::string(what) + ": an AsyncRunner is running this space on its loop thread; "
                                        "call it there (AsyncRunner::post) or after stop()");
    }
}

inline AccessGate::Structure::Structure(AccessGate& gate, const char* what) : m_gate(gate) {
    const std::thread::id self = std::this_thread::get_id();
    if (gate.m_holder.load(std::memory_order_acquire) == self) return;  // nested on this thread
    gate.check_claim(what);
    std::unique_lock turn(gate.m_structure);
    int expected = kFree;
    if (!gate.m_state.compare_exchange_strong(expected, kStructure, std::memory_order_acquire)) {
        throw Error(std::string(what) + ": an update is running on another thread; call it between updates "
                                        "(or on the loop thread with AsyncRunner::post)");
    }
    gate.m_holder.store(self, std::memory_order_release);
    turn.release();  // held until the destructor
    m_took = true;
}

inline AccessGate::Structure::Structure(AccessGate& gate, std::try_to_lock_t) : m_gate(gate) {
    const std::thread::id self = std::this_thread::get_id();
    if (gate.m_holder.load(std::memory_order_acquire) == self) return;  // nested on this thread
    m_owns = false;
    if (gate.claimed_by_other()) return;
    std::unique_lock turn(gate.m_structure, std::try_to_lock);
    int expected = kFree;
    if (!turn.owns_lock() || !gate.m_state.compare_exchange_strong(expected, kStructure, std::memory_order_acquire)) {
        return;
    }
    gate.m_holder.store(self, std::memory_order_release);
    turn.release();  // held until the destructor
    m_took = true;
    m_owns = true;
}

inline AccessGate::Structure::~Structure() {
    if (!m_took) return;
    m_gate.m_holder.store(std::thread::id{}, std::memory_order_release);
    m_gate.m_state.store(kFree, std::memory_order_release);
    m_gate.m_structure.unlock();
}

inline AccessGate::Update::Update(AccessGate& gate, const char* what) : m_gate(gate) {
    const std::thread::id self = std::this_thread::get_id();
    if (gate.m_holder.load(std::memory_order_acquire) == self) {
        // An update inside a structural call or another update of this thread.
        throw Error(std::string(what) + ": called from inside a call that is changing this space");
    }
    gate.check_claim(what);
    int expected = kFree;
    while (!gate.m_state.compare_exchange_weak(expected, kUpdate, std::memory_order_acquire)) {
        if (expected == kUpdate) throw Error(std::string(what) + ": another thread's update is running");
        expected = kFree;
        std::this_thread::yield();  // a structural call on another thread: short
    }
    gate.m_holder.store(self, std::memory_order_release);
    m_took = true;
}

inline AccessGate::Update::~Update() {
    if (!m_took) return;
    m_gate.m_holder.store(std::thread::id{}, std::memory_order_release);
    m_gate.m_state.store(kFree, std::memory_order_release);
}

}  // namespace spindle
