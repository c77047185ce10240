// Affinity layouts: which hardware thread runs the game, the physics loop and each
// scheduler worker. A layout names hardware threads of a *modelled* machine (a hwloc
// synthetic description, or the real machine); map_layout() places them on a real
// machine deterministically (design.md section 4).
#pragma once

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <spindle/platform/topology.hpp>

namespace spindle {

struct Layout {
    std::string name;
    std::string source;             // file it came from (or "<embedded>")
    std::string model;              // hwloc synthetic description, or "machine"
    unsigned game = 0;              // modelled hardware thread (logical PU index)
    unsigned physics = 0;           // modelled hardware thread of the physics loop
    std::vector<unsigned> workers;  // modelled hardware threads of the workers, in order

    // Parses TOML. Unknown keys, wrong types, out-of-range, duplicate or missing
    // threads throw spindle::Error "source:line:column: <what was expected>".
    // A model of "machine" is resolved against `machine` (the real one by default).
    static Layout parse(std::string_view toml_text, std::string_view source_name, const Topology* machine = nullptr);
    static Layout load(const std::string& path, const Topology* machine = nullptr);
    // The layout used when none is given: the real machine, workers on every PU,
    // game and physics loop on the first PU.
    static Layout native(const Topology& machine);

    // The modelled machine as a Topology (the real one when model == "machine").
    Topology model_topology(const Topology& machine) const;
};

struct RolePlacement {
    std::string role;            // "game", "physics", "worker 0", ...
    unsigned modelled_pu = 0;    // logical PU in the model
    unsigned modelled_core = 0;  // logical core in the model
    unsigned real_pu = 0;        // OS index of the real PU it runs on
    unsigned real_core = 0;      // logical core on the real machine
};

struct LayoutMapping {
    RolePlacement game;
    RolePlacement physics;
    std::vector<RolePlacement> workers;
    // True when the physics loop thread is itself worker `physics_worker` (its
    // hardware thread is in the worker list), as in the seed's Xbox 360 example.
    std::optional<unsigned> physics_worker;
    bool model_larger_than_machine = false;  // threads share: modelled core c -> real core c mod n
    std::vector<std::string> shared;         // one line per real PU that several roles share

    // Real PU OS indices of the workers, in worker order.
    std::vector<unsigned> worker_pus() const;
    // The whole table, as `spindle layout` prints it.
    std::string describe() const;
};

// Modelled core c -> real core (c mod real cores); modelled PU p of that core -> the
// (p mod n)-th PU of the real core. Deterministic and total.
LayoutMapping map_layout(const Layout& layout, const Topology& model, const Topology& real);

}  // namespace spindle
