// The view page's commands (apps/spindle/view_commands.cpp): good ones parse to what
// they say; malformed, hostile, oversized or out-of-mode ones are refused with a message
// naming what was wrong, and never crash the parser.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>

#include "view_commands.hpp"

namespace spindle::app {
namespace {

ParsedCommand live(std::string_view text) { return parse_view_command(text, /*replay=*/false); }
ParsedCommand replay(std::string_view text) { return parse_view_command(text, /*replay=*/true); }

void expect_refused(const ParsedCommand& parsed, const std::string& reason) {
    EXPECT_FALSE(parsed.ok);
    EXPECT_NE(parsed.error.find(reason), std::string::npos) << "error was: " << parsed.error;
}

TEST(ViewCommand_Parse, GoodCommandsSayWhatTheyMean) {
    ParsedCommand p = live("shoot 1 2 3 0 0 -2");
    ASSERT_TRUE(p.ok) << p.error;
    EXPECT_EQ(p.command.action, ViewAction::Shoot);
    EXPECT_EQ(p.command.origin, Vec3(1, 2, 3));
    EXPECT_EQ(p.command.direction, Vec3(0, 0, -1));  // made unit length

    p = live("  drag   0.5 1e1 -3   1 0 0\r\n");  // extra spaces and a line end are fine
    ASSERT_TRUE(p.ok) << p.error;
    EXPECT_EQ(p.command.action, ViewAction::Drag);
    EXPECT_EQ(p.command.origin, Vec3(0.5, 10, -3));

    p = live("speed 0.25");
    ASSERT_TRUE(p.ok) << p.error;
    EXPECT_EQ(p.command.action, ViewAction::Speed);
    EXPECT_EQ(p.command.value, 0.25);

    p = live("interpolate off");
    ASSERT_TRUE(p.ok) << p.error;
    EXPECT_EQ(p.command.value, 0);
    EXPECT_TRUE(live("interpolate on").ok);
    p = live("contacts on");
    ASSERT_TRUE(p.ok) << p.error;
    EXPECT_EQ(p.command.action, ViewAction::Contacts);
    EXPECT_EQ(p.command.value, 1);
    EXPECT_EQ(live("contacts off").command.value, 0);
    for (const char* word : {"pause", "resume", "step", "drop", "release"}) EXPECT_TRUE(live(word).ok) << word;

    p = replay("seek 2.5");
    ASSERT_TRUE(p.ok) << p.error;
    EXPECT_EQ(p.command.action, ViewAction::Seek);
    EXPECT_EQ(p.command.value, 2.5);
    EXPECT_TRUE(replay("speed 4").ok);  // a replay may run fast; the live view only slow
}

TEST(ViewCommand_Parse, MalformedCommandsAreRefusedWithTheReason) {
    expect_refused(live(""), "empty command");
    expect_refused(live("   "), "empty command");
    expect_refused(live("launch 1 2 3"), "unknown command 'launch'");
    expect_refused(live("PAUSE"), "unknown command 'PAUSE'");
    expect_refused(live("shoot 1 2 3"), "'shoot' takes 6 values, got 3");
    expect_refused(live("pause now"), "'pause' takes 0 values, got 1");
    expect_refused(live("shoot 1 2 3 0 0 x"), "value 6 'x' is not a finite number");
    expect_refused(live("shoot 1 2 3 0 0 1x"), "value 6 '1x' is not a finite number");
    expect_refused(live("shoot 1 2 3 0 0 nan"), "is not a finite number");
    expect_refused(live("shoot 1 2 3 0 0 inf"), "is not a finite number");
    expect_refused(live("shoot 1 2 3 0 0 1e999"), "is not a finite number");
    expect_refused(live("shoot 0x10 2 3 0 0 1"), "is not a finite number");
    expect_refused(live("shoot 1 2 3 0 0 0"), "direction has no length");
    expect_refused(live("grab 1e9 0 0 0 0 1"), "origin is further than");
    expect_refused(live("interpolate yes"), "takes on or off, got 'yes'");
    expect_refused(live("contacts 1"), "'contacts' takes on or off, got '1'");
}

TEST(ViewCommand_Parse, ValuesOutOfRangeAreRefused) {
    expect_refused(live("speed 2"), "'speed' must be in 0.01..1");  // live: slow motion only
    expect_refused(live("speed 0"), "'speed' must be in");
    expect_refused(live("speed -1"), "'speed' must be in");
    expect_refused(replay("speed 9"), "'speed' must be in 0.01..8");
    expect_refused(replay("seek -1"), "'seek' must be >= 0");
}

TEST(ViewCommand_Parse, CommandsOfTheOtherModeAreRefused) {
    expect_refused(live("seek 1"), "'seek' is only for a replay");
    for (const char* text : {"shoot 0 0 0 0 0 1", "grab 0 0 0 0 0 1", "drag 0 0 0 0 0 1", "drop", "release",
                             "interpolate on", "contacts on"}) {
        expect_refused(replay(text), "is not for a replay");
    }
}

TEST(ViewCommand_Parse, HostileBytesAndOversizedCommandsAreRefused) {
    expect_refused(live(std::string("pause\0", 6)), "not printable ASCII");
    expect_refused(live("pause\x01"), "not printable ASCII");
    expect_refused(live("shoot\t1 2 3 0 0 1"), "not printable ASCII");
    expect_refused(live("p\xc3\xa4use"), "not printable ASCII");
    expect_refused(live(std::string(kMaxCommandBytes + 1, 'a')), "at most 256 allowed");
    EXPECT_FALSE(live(std::string(kMaxCommandBytes, ' ')).ok);  // at the limit: parsed (and empty)
}

// Random lines of the command alphabet never crash the parser, and what it accepts is in range.
TEST(ViewCommand_Parse, RandomInputNeverCrashesAndAcceptedValuesAreSane) {
    const std::string alphabet = "shootgrabdragspeedseekinterpolate on off 0123456789.-+eE naninf\x01\xff,";
    std::mt19937 random(7);
    std::uniform_int_distribution<std::size_t> length(0, 300), pick(0, alphabet.size() - 1);
    for (int i = 0; i < 20000; ++i) {
        std::string text(length(random), ' ');
        for (char& c : text) c = alphabet[pick(random)];
        for (const bool mode : {false, true}) {
            const ParsedCommand p = parse_view_command(text, mode);
            if (!p.ok) {
                EXPECT_FALSE(p.error.empty());
                continue;
            }
            EXPECT_TRUE(p.command.origin.allFinite());
            EXPECT_NEAR(p.command.direction.norm(), 1.0, 1e-9);
            EXPECT_TRUE(std::isfinite(p.command.value));
        }
    }
}

}  // namespace
}  // namespace spindle::app
