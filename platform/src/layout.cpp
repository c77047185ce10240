// Layout files (TOML) and the deterministic mapping from modelled to real PUs.
#include <spindle/platform/error.hpp>
#include <spindle/platform/layout.hpp>

#include <toml++/toml.h>

#include <algorithm>
#include <fstream>
#include <map>
#include <set>
#include <sstream>

namespace spindle {
namespace {

constexpr const char* kKeys[] = {"name", "description", "model", "game", "physics", "workers"};

[[noreturn]] void fail(std::string_view source, const toml::source_region& where, const std::string& what) {
    std::ostringstream out;
    out << source << ':' << where.begin.line << ':' << where.begin.column << ": " << what;
    throw Error(out.str());
}

// A hardware thread index: an integer in [0, count).
unsigned read_thread(std::string_view source, const toml::node& node, std::string_view key, unsigned count) {
    const auto value = node.value_exact<int64_t>();
    if (!value) fail(source, node.source(), std::string(key) + ": expected an integer hardware thread index");
    if (*value < 0 || *value >= static_cast<int64_t>(count)) {
        fail(source, node.source(),
             std::string(key) + ": hardware thread " + std::to_string(*value) + " does not exist; the model has " +
                 std::to_string(count) + " (0.." + std::to_string(count - 1) + ")");
    }
    return static_cast<unsigned>(*value);
}

}  // namespace

Layout Layout::parse(std::string_view toml_text, std::string_view source_name, const Topology* machine) {
    toml::table table;
    try {
        table = toml::parse(toml_text, source_name);
    } catch (const toml::parse_error& e) {
        fail(source_name, e.source(), std::string(e.description()));
    }
    for (auto&& [key, node] : table) {
        if (std::find(std::begin(kKeys), std::end(kKeys), key.str()) == std::end(kKeys)) {
            fail(source_name, key.source(),
                 "unknown key '" + std::string(key.str()) +
                     "' (expected one of: name, description, model, game, physics, workers)");
        }
    }
    const toml::source_region whole{{1, 1}, {1, 1}, nullptr};
    auto require = [&](const char* key) -> const toml::node& {
        const toml::node* node = table.get(key);
        if (!node) fail(source_name, whole, std::string("missing key '") + key + "'");
        return *node;
    };

    Layout layout;
    layout.source = std::string(source_name);
    if (const toml::node* name = table.get("name")) {
        if (!name->is_string()) fail(source_name, name->source(), "name: expected a string");
        layout.name = name->value<std::string>().value();
    }
    if (const toml::node* d = table.get("description"); d && !d->is_string()) {
        fail(source_name, d->source(), "description: expected a string");
    }
    const toml::node& model = require("model");
    if (!model.is_string()) {
        fail(source_name, model.source(),
             "model: expected a string, a hwloc synthetic topology such as \"package:1 core:3 pu:2\" or \"machine\"");
    }
    layout.model = model.value<std::string>().value();
    Topology model_topology = [&] {
        try {
            return layout.model_topology(machine ? *machine : Topology::from_system());
        } catch (const Error& e) {
            fail(source_name, model.source(), std::string("model: ") + e.what());
        }
    }();
    const auto count = static_cast<unsigned>(model_topology.pus().size());
    layout.game = read_thread(source_name, require("game"), "game", count);
    layout.physics = read_thread(source_name, require("physics"), "physics", count);

    const toml::node& workers = require("workers");
    if (workers.is_string() && workers.value<std::string>() == "all") {
        for (unsigned i = 0; i < count; ++i) layout.workers.push_back(i);
    } else if (const toml::array* list = workers.as_array()) {
        if (list->empty()) fail(source_name, workers.source(), "workers: expected at least one hardware thread");
        std::set<unsigned> seen;
        for (const toml::node& entry : *list) {
            const unsigned thread = read_thread(source_name, entry, "workers", count);
            if (!seen.insert(thread).second) {
                fail(source_name, entry.source(),
                     "workers: hardware thread " + std::to_string(thread) + " is listed twice");
            }
            layout.workers.push_back(thread);
        }
    } else {
        fail(source_name, workers.source(), "workers: expected an array of hardware thread indices or \"all\"");
    }
    if (layout.name.empty()) layout.name = std::string(source_name);
    return layout;
}

Layout Layout::load(const std::string& path, const Topology* machine) {
    std::ifstream in(path);
    if (!in) throw Error(path + ": cannot open layout file");
    std::stringstream text;
    text << in.rdbuf();
    return parse(text.str(), path, machine);
}

Layout Layout::native(const Topology& machine) {
    Layout layout;
    layout.name = "native";
    layout.source = "<embedded>";
    layout.model = "machine";
    layout.game = 0;
    layout.physics = 0;
    for (unsigned i = 0; i < machine.pus().size(); ++i) layout.workers.push_back(i);
    return layout;
}

Topology Layout::model_topology(const Topology& machine) const {
    return model == "machine" ? machine : Topology::from_synthetic(model);
}

std::vector<unsigned> LayoutMapping::worker_pus() const {
    std::vector<unsigned> result;
    for (const RolePlacement& w : workers) result.push_back(w.real_pu);
    return result;
}

std::string LayoutMapping::describe() const {
    std::ostringstream out;
    out << "role        modelled thread  modelled core  ->  real PU (os)  real core\n";
    auto row = [&](const RolePlacement& r) {
        out.width(12);
        out << std::left << r.role;
        out.width(17);
        out << r.modelled_pu;
        out.width(15);
        out << r.modelled_core << "->  ";
        out.width(14);
        out << r.real_pu << r.real_core << '\n';
    };
    row(game);
    row(physics);
    for (const RolePlacement& w : workers) row(w);
    if (physics_worker) out << "the physics loop thread is worker " << *physics_worker << '\n';
    if (model_larger_than_machine) {
        out << "note: the modelled machine has more cores than this one; modelled core c runs on real core "
               "c mod n, so some threads share\n";
    }
    for (const std::string& line : shared) out << "note: " << line << '\n';
    return out.str();
}

LayoutMapping map_layout(const Layout& layout, const Topology& model, const Topology& real) {
    const auto real_cores = static_cast<unsigned>(real.cores().size());
    auto place = [&](std::string role, unsigned modelled_pu) {
        if (modelled_pu >= model.pus().size()) {
            throw Error(layout.source + ": " + role + " names hardware thread " + std::to_string(modelled_pu) +
                        ", which the model does not have");
        }
        const PuInfo& pu = model.pus()[modelled_pu];
        const CoreInfo& modelled_core = model.cores()[pu.core];
        const auto rank = static_cast<unsigned>(
            std::find(modelled_core.pus.begin(), modelled_core.pus.end(), modelled_pu) - modelled_core.pus.begin());
        const CoreInfo& core = real.cores()[pu.core % real_cores];
        const PuInfo& target = real.pus()[core.pus[rank % core.pus.size()]];
        return RolePlacement{std::move(role), modelled_pu, pu.core, target.os_index, core.logical};
    };

    LayoutMapping mapping;
    mapping.game = place("game", layout.game);
    mapping.physics = place("physics", layout.physics);
    for (unsigned i = 0; i < layout.workers.size(); ++i) {
        mapping.workers.push_back(place("worker " + std::to_string(i), layout.workers[i]));
        if (layout.workers[i] == layout.physics && !mapping.physics_worker) mapping.physics_worker = i;
    }
    mapping.model_larger_than_machine = model.cores().size() > real.cores().size();

    // Which real PUs carry more than one role (the physics loop thread that is also a
    // worker is one thread, not two roles).
    std::map<unsigned, std::vector<std::string>> by_pu;
    by_pu[mapping.game.real_pu].push_back("game");
    by_pu[mapping.physics.real_pu].push_back("physics");
    for (unsigned i = 0; i < mapping.workers.size(); ++i) {
        if (mapping.physics_worker && *mapping.physics_worker == i) continue;
        by_pu[mapping.workers[i].real_pu].push_back(mapping.workers[i].role);
    }
    for (const auto& [pu, roles] : by_pu) {
        if (roles.size() < 2) continue;
        std::string line = "real PU " + std::to_string(pu) + " is shared by";
        for (const std::string& r : roles) line += " " + r + ",";
        line.pop_back();
        mapping.shared.push_back(line);
    }
    return mapping;
}

}  // namespace spindle
