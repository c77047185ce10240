// ViewServer: the HTTP side of `spindle view`, on cpp-httplib's own threads. It serves
// the page, three.js from Debian's libjs-three, and what the game thread published last
// (scene description, frame, stats); the page polls GET /frame for the newest frame
// (binary), so a slow page skips frames instead of queueing them. POST /command takes
// one command line (view_commands.hpp); a bad one gets HTTP 400 and its error, and every
// refused request is logged on stderr. The game thread never waits for the network: it
// swaps a pointer to publish and takes the queued commands once a frame.
#pragma once

#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "view_commands.hpp"

namespace httplib {
class Server;
}

namespace spindle::app {

struct ViewAssets {
    std::string html;           // the page
    std::string script;         // its JavaScript
    std::string three_js_path;  // three.min.js from libjs-three, read when the server starts
};

// The page as built into the program, and where this system keeps three.js (generated
// from apps/spindle/web: view_assets.cpp).
ViewAssets view_assets();

class ViewServer {
public:
    // Commands waiting for the game thread beyond this are refused (HTTP 503).
    static constexpr std::size_t kMaxQueuedCommands = 256;

    // Binds 127.0.0.1:port (0: a free port) and starts serving. spindle::Error if the port
    // cannot be bound or three.js cannot be read.
    ViewServer(int port, ViewAssets assets, bool replay);
    // Stops serving and joins its threads.
    ~ViewServer();
    ViewServer(const ViewServer&) = delete;
    ViewServer& operator=(const ViewServer&) = delete;

    int port() const noexcept { return m_port; }

    // Any thread (the game thread): what the next requests get.
    void publish_scene(std::string json);
    void publish_frame(std::string frame);
    void publish_stats(std::string json);
    // The commands accepted since the last call, in the order they came.
    std::vector<ViewCommand> take_commands();
    std::uint64_t refused() const;  // requests answered with an error so far

private:
    void route();

    std::unique_ptr<httplib::Server> m_http;
    std::thread m_thread;
    int m_port = 0;
    bool m_replay = false;
    ViewAssets m_assets;
    std::string m_three_js;

    mutable std::mutex m_lock;  // everything below
    std::shared_ptr<const std::string> m_scene, m_frame, m_stats;
    std::vector<ViewCommand> m_commands;
    std::uint64_t m_refused = 0;
};

}  // namespace spindle::app
