#include <spindle/platform/error.hpp>
#include <spindle/platform/layout.hpp>

#include <gtest/gtest.h>

#include <string>

using spindle::Layout;
using spindle::LayoutMapping;
using spindle::Topology;

namespace {

std::string config(const std::string& name) { return std::string(SPINDLE_SOURCE_DIR) + "/configs/layouts/" + name; }

LayoutMapping map_xbox_onto(const char* real_description) {
    const Topology real = Topology::from_synthetic(real_description);
    const Layout layout = Layout::load(config("xbox360.toml"), &real);
    return spindle::map_layout(layout, layout.model_topology(real), real);
}

struct Expected {
    unsigned game, physics, worker0, worker1;
};

void expect_roles(const LayoutMapping& m, Expected e) {
    EXPECT_EQ(m.game.real_pu, e.game);
    EXPECT_EQ(m.physics.real_pu, e.physics);
    ASSERT_EQ(m.workers.size(), 2u);
    EXPECT_EQ(m.workers[0].real_pu, e.worker0);
    EXPECT_EQ(m.workers[1].real_pu, e.worker1);
}

// Parses text and returns the error message (empty if it parsed).
std::string error_of(const std::string& text) {
    const Topology machine = Topology::from_synthetic("package:1 core:2 pu:1");
    try {
        Layout::parse(text, "bad.toml", &machine);
    } catch (const spindle::Error& e) {
        return e.what();
    }
    return {};
}

}  // namespace

TEST(Layout, Xbox360FileModelsTheSeedExample) {
    const Topology real = Topology::from_synthetic("package:1 core:3 pu:2");
    const Layout layout = Layout::load(config("xbox360.toml"), &real);
    EXPECT_EQ(layout.model, "package:1 core:3 pu:2");
    EXPECT_EQ(layout.game, 1u);
    EXPECT_EQ(layout.physics, 3u);
    EXPECT_EQ(layout.workers, (std::vector<unsigned>{3, 5}));
    const LayoutMapping m = spindle::map_layout(layout, layout.model_topology(real), real);
    expect_roles(m, {1, 3, 3, 5});
    ASSERT_TRUE(m.physics_worker.has_value());
    EXPECT_EQ(*m.physics_worker, 0u);
    EXPECT_TRUE(m.shared.empty());
    EXPECT_EQ(m.game.modelled_core, 0u);
    EXPECT_EQ(m.physics.modelled_core, 1u);
    EXPECT_EQ(m.workers[1].modelled_core, 2u);
}

TEST(Layout, Xbox360OntoOnePuSharesEverything) {
    const LayoutMapping m = map_xbox_onto("package:1 core:1 pu:1");
    expect_roles(m, {0, 0, 0, 0});
    EXPECT_TRUE(m.model_larger_than_machine);
    ASSERT_EQ(m.shared.size(), 1u);
    EXPECT_NE(m.describe().find("shared"), std::string::npos);
}

TEST(Layout, Xbox360OntoTwoPusWrapsCoreTwoOntoCoreZero) {
    const LayoutMapping m = map_xbox_onto("package:1 core:2 pu:1");
    expect_roles(m, {0, 1, 1, 0});
    EXPECT_TRUE(m.model_larger_than_machine);
    ASSERT_EQ(m.shared.size(), 1u);  // game and worker 1 on PU 0
    EXPECT_NE(m.shared[0].find("game"), std::string::npos);
    EXPECT_NE(m.shared[0].find("worker 1"), std::string::npos);
}

TEST(Layout, Xbox360OntoFourPus) {
    const LayoutMapping m = map_xbox_onto("package:1 core:4 pu:1");
    expect_roles(m, {0, 1, 1, 2});
    EXPECT_FALSE(m.model_larger_than_machine);
    EXPECT_TRUE(m.shared.empty());
}

TEST(Layout, Xbox360OntoTwoSmtCores) {
    const LayoutMapping m = map_xbox_onto("package:1 core:2 pu:2");
    expect_roles(m, {1, 3, 3, 1});
}

TEST(Layout, Xbox360OntoSixteenPus) {
    const LayoutMapping m = map_xbox_onto("package:1 core:16 pu:1");
    expect_roles(m, {0, 1, 1, 2});
}

TEST(Layout, Xbox360OntoSmtMachineKeepsThreadRanks) {
    const LayoutMapping m = map_xbox_onto("package:2 core:4 pu:2");
    expect_roles(m, {1, 3, 3, 5});
    EXPECT_FALSE(m.model_larger_than_machine);
}

TEST(Layout, EveryShippedLayoutLoadsAndMaps) {
    const Topology real = Topology::from_synthetic("package:1 core:2 pu:1");
    for (const char* name : {"xbox360.toml", "native.toml", "single.toml", "two-core.toml"}) {
        SCOPED_TRACE(name);
        const Layout layout = Layout::load(config(name), &real);
        const LayoutMapping m = spindle::map_layout(layout, layout.model_topology(real), real);
        EXPECT_FALSE(m.workers.empty());
        for (const auto& w : m.workers) EXPECT_LT(w.real_pu, 2u);
    }
}

TEST(Layout, NativeUsesEveryPuOfTheMachine) {
    const Topology real = Topology::from_synthetic("package:1 core:4 pu:2");
    const Layout layout = Layout::load(config("native.toml"), &real);
    EXPECT_EQ(layout.workers.size(), 8u);
    const LayoutMapping m = spindle::map_layout(layout, layout.model_topology(real), real);
    for (unsigned i = 0; i < 8; ++i) EXPECT_EQ(m.workers[i].real_pu, real.pus()[i].os_index);
}

TEST(LayoutErrors, UnknownKeyNamesItsLine) {
    const std::string e =
        error_of("model = \"package:1 core:3 pu:2\"\ngame = 1\nphysics = 3\nworkers = [3]\nwokers = 2\n");
    EXPECT_NE(e.find("bad.toml:5:"), std::string::npos) << e;
    EXPECT_NE(e.find("unknown key 'wokers'"), std::string::npos) << e;
}

TEST(LayoutErrors, WrongTypeNamesItsLine) {
    const std::string e = error_of("model = \"package:1 core:3 pu:2\"\ngame = \"one\"\nphysics = 3\nworkers = [3]\n");
    EXPECT_NE(e.find("bad.toml:2:"), std::string::npos) << e;
    EXPECT_NE(e.find("game: expected an integer"), std::string::npos) << e;
}

TEST(LayoutErrors, ThreadSixInASixThreadModelIsOutOfRange) {
    const std::string e = error_of("model = \"package:1 core:3 pu:2\"\ngame = 1\nphysics = 3\nworkers = [3,\n  6]\n");
    EXPECT_NE(e.find("bad.toml:5:"), std::string::npos) << e;
    EXPECT_NE(e.find("hardware thread 6 does not exist"), std::string::npos) << e;
}

TEST(LayoutErrors, DuplicateWorkerNamesItsLine) {
    const std::string e = error_of("model = \"package:1 core:3 pu:2\"\ngame = 1\nphysics = 3\n\nworkers = [3, 3]\n");
    EXPECT_NE(e.find("bad.toml:5:"), std::string::npos) << e;
    EXPECT_NE(e.find("listed twice"), std::string::npos) << e;
}

TEST(LayoutErrors, EmptyWorkersNamesItsLine) {
    const std::string e = error_of("model = \"package:1 core:3 pu:2\"\ngame = 1\nphysics = 3\nworkers = []\n");
    EXPECT_NE(e.find("bad.toml:4:"), std::string::npos) << e;
    EXPECT_NE(e.find("at least one"), std::string::npos) << e;
}

TEST(LayoutErrors, SyntaxErrorAndBadModelAreReported) {
    EXPECT_NE(error_of("model = \"package:1\ngame = 1\n").find("bad.toml:1:"), std::string::npos);
    const std::string e = error_of("model = \"package:1 nonsense:3\"\ngame = 0\nphysics = 0\nworkers = [0]\n");
    EXPECT_NE(e.find("bad.toml:1:"), std::string::npos) << e;
    EXPECT_NE(error_of("game = 0\nphysics = 0\nworkers = [0]\n").find("missing key 'model'"), std::string::npos);
}
