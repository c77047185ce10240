// What the `spindle view` page may ask of the program: one short line of text per
// request (POST /command), parsed and checked here before anything acts on it. Anything
// else, too long, malformed, out of range or not for this mode, is an error message
// for the reply (HTTP 400) and the log; nothing the page sends reaches the space
// unchecked.
//
//   pause | resume | step | drop | release
//   speed S                       live: 0.01..1 (slow motion); replay: 0.01..8
//   interpolate on|off            live only: blended or newest-step reads
//   contacts on|off               live only: the touching points in every frame, or none
//   shoot OX OY OZ DX DY DZ       live only: a ball from O along D (a camera ray)
//   grab OX OY OZ DX DY DZ        live only: take the body the ray hits
//   drag OX OY OZ DX DY DZ        live only: move the grabbed body toward the ray
//   seek T                        replay only: to T seconds into the record
#pragma once

#include <cstddef>
#include <string>
#include <string_view>

#include <spindle/engine/math.hpp>

namespace spindle::app {

enum class ViewAction { Pause, Resume, Step, Drop, Release, Speed, Interpolate, Contacts, Shoot, Grab, Drag, Seek };

struct ViewCommand {
    ViewAction action = ViewAction::Pause;
    Vec3 origin = Vec3::Zero();  // shoot, grab, drag: the ray, direction unit length
    Vec3 direction = Vec3::UnitZ();
    double value = 0;  // speed, seek (seconds), interpolate and contacts (1 on, 0 off)
};

// Longer requests are refused before they are read as a command.
inline constexpr std::size_t kMaxCommandBytes = 256;
// Ray origins further out than this are refused (the page's camera never goes there).
inline constexpr double kMaxCoordinate = 1e5;

struct ParsedCommand {
    bool ok = false;
    ViewCommand command;  // when ok
    std::string error;    // otherwise: what was wrong, for the reply and the log
};

// replay: the page plays a record (spindle view --replay), where only pause, resume,
// step, speed and seek mean anything.
ParsedCommand parse_view_command(std::string_view text, bool replay);

}  // namespace spindle::app
