// What the scene suites share: the message a bad scene file's parse gives, and a check
// that it names the file, the line and what was wrong.
#pragma once

#include <spindle/platform/error.hpp>
#include <spindle/scene/scene.hpp>

#include <gtest/gtest.h>

#include <string>

namespace spindle::test {

// The message of the spindle::Error that parsing `text` (as "bad.toml") throws.
inline std::string parse_error(const std::string& text) {
    try {
        parse_scene(text, "bad.toml");
    } catch (const Error& e) {
        return e.what();
    }
    return "(no error)";
}

}  // namespace spindle::test

#define EXPECT_REJECTED(text, where, what)                                                                \
    do {                                                                                                  \
        const std::string message = spindle::test::parse_error(text);                                     \
        EXPECT_NE(message.find(std::string("bad.toml:") + (where) + ": "), std::string::npos) << message; \
        EXPECT_NE(message.find(what), std::string::npos) << message;                                      \
    } while (0)
