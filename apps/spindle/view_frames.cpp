// The view page's scene description (JSON) and frames (binary), view_frames.hpp.
#include "view_frames.hpp"

#include <bit>
#include <cstdio>
#include <cstring>

namespace spindle::app {
namespace {

static_assert(std::endian::native == std::endian::little, "frames are written as the page reads them: little-endian");

void append_number(std::string& out, double value) {
    char text[32];
    const int n = std::snprintf(text, sizeof text, "%.9g", value);
    out.append(text, static_cast<std::size_t>(n));
}

void append_vec(std::string& out, const Vec3& v) {
    out += '[';
    append_number(out, v.x());
    out += ',';
    append_number(out, v.y());
    out += ',';
    append_number(out, v.z());
    out += ']';
}

const char* shape_name(ShapeType type) {
    switch (type) {
        case ShapeType::Sphere: return "sphere";
        case ShapeType::Capsule: return "capsule";
        case ShapeType::Box: return "box";
        case ShapeType::ConvexHull: return "hull";
        case ShapeType::Plane: return "plane";
        case ShapeType::TriangleMesh: return "mesh";
        default: return "unknown";
    }
}

void append_shape(std::string& out, const ShapeSpec& s) {
    out += "{\"type\":\"";
    out += shape_name(s.type);
    out += "\",\"radius\":";
    append_number(out, s.radius);
    out += ",\"half_height\":";
    append_number(out, s.half_height);
    out += ",\"half_extents\":";
    append_vec(out, s.half_extents);
    out += ",\"normal\":";
    append_vec(out, s.normal);
    out += ",\"offset\":";
    append_number(out, s.offset);
    out += ",\"points\":[";
    for (std::size_t i = 0; i < s.points.size(); ++i) {
        if (i) out += ',';
        append_vec(out, s.points[i]);
    }
    out += "],\"indices\":[";
    for (std::size_t i = 0; i < s.indices.size(); ++i) {
        if (i) out += ',';
        out += std::to_string(s.indices[i]);
    }
    out += "]}";
}

template <typename T>
void put(std::string& out, T value) {
    char bytes[sizeof(T)];
    std::memcpy(bytes, &value, sizeof(T));
    out.append(bytes, sizeof(T));
}

}  // namespace

std::string json_string(std::string_view text) {
    std::string out = "\"";
    for (const char c : text) {
        if (c == '"' || c == '\\') {
            out += '\\';
            out += c;
        } else if (static_cast<unsigned char>(c) < 0x20) {
            char escape[8];
            std::snprintf(escape, sizeof escape, "\\u%04x", static_cast<unsigned>(c));
            out += escape;
        } else {
            out += c;
        }
    }
    out += '"';
    return out;
}

std::string scene_json(std::uint32_t version, std::string_view name, std::span<const ShapeSpec> shapes,
                       std::span<const ViewBody> bodies) {
    std::string out = "{\"version\":" + std::to_string(version) + ",\"name\":" + json_string(name) + ",\"shapes\":[";
    for (std::size_t i = 0; i < shapes.size(); ++i) {
        if (i) out += ',';
        append_shape(out, shapes[i]);
    }
    out += "],\"bodies\":[";
    for (std::size_t i = 0; i < bodies.size(); ++i) {
        if (i) out += ',';
        out += "[" + std::to_string(bodies[i].shape) + "," + (bodies[i].moving ? "1" : "0") + "," +
               (bodies[i].projectile ? "1" : "0") + "," + (bodies[i].sensor ? "1" : "0") + "]";
    }
    out += "]}";
    return out;
}

std::string encode_frame(const FrameHeader& header, std::span<const MotionState> states,
                         std::span<const std::uint8_t> asleep, std::span<const ContactMark> contacts) {
    std::string out;
    out.reserve(40 + states.size() * 32 + contacts.size() * 28);
    put(out, kFrameMagic);
    put(out, header.scene_version);
    put(out, static_cast<std::uint32_t>(states.size()));
    put(out, static_cast<std::uint32_t>(contacts.size()));
    put(out, header.flags);
    put(out, std::uint32_t{0});
    put(out, header.simulated_seconds);
    put(out, header.steps);
    for (std::size_t i = 0; i < states.size(); ++i) {
        const MotionState& s = states[i];
        for (const double v : {s.position.x(), s.position.y(), s.position.z(), s.orientation.x(), s.orientation.y(),
                               s.orientation.z(), s.orientation.w()}) {
            put(out, static_cast<float>(v));
        }
        put(out, i < asleep.size() && asleep[i] ? 1.0f : 0.0f);
    }
    for (const ContactMark& c : contacts) {
        for (const double v :
             {c.point.x(), c.point.y(), c.point.z(), c.normal.x(), c.normal.y(), c.normal.z(), c.age}) {
            put(out, static_cast<float>(v));
        }
    }
    return out;
}

}  // namespace spindle::app
