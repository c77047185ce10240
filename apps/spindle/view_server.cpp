// ViewServer: cpp-httplib routes for the view page (view_server.hpp).
#include "view_server.hpp"

#include <spindle/platform/error.hpp>

#include <httplib.h>
#include <sys/socket.h>

#include <cstdio>
#include <fstream>
#include <sstream>

namespace spindle::app {
namespace {

constexpr char kLocalhost[] = "127.0.0.1";
// Bodies larger than a command are cut off by httplib (413) before a handler sees them.
constexpr std::size_t kMaxPayload = 4096;
// Threads serving requests: a page keeps a couple of connections open; a few spare
// ones let a second page or a test's requests through.
constexpr std::size_t kServerThreads = 6;

std::string read_whole(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    if (!in) {
        throw Error(path + ": cannot read three.js (Debian's libjs-three package; scripts/setup.sh installs it)");
    }
    std::stringstream text;
    text << in.rdbuf();
    return text.str();
}

}  // namespace

ViewServer::ViewServer(int port, ViewAssets assets, bool replay)
    : m_http(std::make_unique<httplib::Server>()), m_replay(replay), m_assets(std::move(assets)) {
    m_three_js = read_whole(m_assets.three_js_path);
    m_http->new_task_queue = [] { return new httplib::ThreadPool(kServerThreads); };
    m_http->set_payload_max_length(kMaxPayload);
    m_http->set_keep_alive_timeout(2);
    // SO_REUSEADDR (a restarted view gets its port back at once) without httplib's default
    // SO_REUSEPORT, which would let a second view share a port the first one holds.
    m_http->set_socket_options([](socket_t sock) {
        int yes = 1;
        ::setsockopt(sock, SOL_SOCKET, SO_REUSEADDR, &yes, sizeof yes);
    });
    route();
    m_port = port == 0 ? m_http->bind_to_any_port(kLocalhost) : (m_http->bind_to_port(kLocalhost, port) ? port : -1);
    if (m_port <= 0) {
        throw Error("cannot listen on " + std::string(kLocalhost) + ":" + std::to_string(port) +
                    " (is another program using it? --port 0 picks a free port)");
    }
    m_thread = std::thread([this] { m_http->listen_after_bind(); });
}

ViewServer::~ViewServer() {
    m_http->stop();
    if (m_thread.joinable()) m_thread.join();
}

void ViewServer::route() {
    httplib::Server& http = *m_http;
    const auto published = [this](std::shared_ptr<const std::string> ViewServer::*slot, const char* type) {
        return [this, slot, type](const httplib::Request&, httplib::Response& res) {
            std::shared_ptr<const std::string> content;
            {
                std::scoped_lock hold(m_lock);
                content = this->*slot;
            }
            res.set_header("Cache-Control", "no-store");
            if (!content) {
                res.status = 503;
                res.set_content("nothing published yet", "text/plain");
                return;
            }
            res.set_content(*content, type);
        };
    };
    http.Get("/", [this](const httplib::Request&, httplib::Response& res) {
        res.set_content(m_assets.html, "text/html; charset=utf-8");
    });
    http.Get("/viewer.js", [this](const httplib::Request&, httplib::Response& res) {
        res.set_content(m_assets.script, "text/javascript; charset=utf-8");
    });
    http.Get("/three.min.js", [this](const httplib::Request&, httplib::Response& res) {
        res.set_content(m_three_js, "text/javascript; charset=utf-8");
    });
    http.Get("/scene", published(&ViewServer::m_scene, "application/json"));
    http.Get("/frame", published(&ViewServer::m_frame, "application/octet-stream"));
    http.Get("/stats", published(&ViewServer::m_stats, "application/json"));
    http.Post("/command", [this](const httplib::Request& req, httplib::Response& res) {
        const ParsedCommand parsed = parse_view_command(req.body, m_replay);
        if (!parsed.ok) {
            res.status = 400;
            res.set_content(parsed.error + "\n", "text/plain");
            return;
        }
        {
            std::scoped_lock hold(m_lock);
            if (m_commands.size() < kMaxQueuedCommands) {
                m_commands.push_back(parsed.command);
                res.set_content("ok\n", "text/plain");
                return;
            }
        }
        res.status = 503;
        res.set_content("too many commands waiting for the game thread\n", "text/plain");
    });
    // httplib answers these itself, with an empty body; the page and the log get a reason.
    http.set_error_handler([](const httplib::Request&, httplib::Response& res) {
        if (!res.body.empty()) return;
        if (res.status == 404) res.set_content("no such page\n", "text/plain");
        if (res.status == 413) {
            res.set_content("request body over " + std::to_string(kMaxPayload) + " bytes\n", "text/plain");
        }
    });
    http.Get("/favicon.ico", [](const httplib::Request&, httplib::Response& res) { res.status = 204; });
    http.set_exception_handler([](const httplib::Request&, httplib::Response& res, std::exception_ptr e) {
        std::string what = "internal error";
        try {
            if (e) std::rethrow_exception(e);
        } catch (const std::exception& x) {
            what = x.what();
        } catch (...) {
        }
        res.status = 500;
        res.set_content(what + "\n", "text/plain");
    });
    // Every refused request, whoever refused it (a handler, or httplib: 404, 413), on stderr.
    http.set_logger([this](const httplib::Request& req, const httplib::Response& res) {
        if (res.status < 400) return;
        {
            std::scoped_lock hold(m_lock);
            m_refused += 1;
        }
        std::string why = res.body;
        while (!why.empty() && why.back() == '\n') why.pop_back();
        std::fprintf(stderr, "spindle view: refused %s %s (%d): %s\n", req.method.c_str(), req.path.c_str(), res.status,
                     why.empty() ? "no reason given" : why.c_str());
    });
}

void ViewServer::publish_scene(std::string json) {
    auto content = std::make_shared<const std::string>(std::move(json));
    std::scoped_lock hold(m_lock);
    m_scene = std::move(content);
}

void ViewServer::publish_frame(std::string frame) {
    auto content = std::make_shared<const std::string>(std::move(frame));
    std::scoped_lock hold(m_lock);
    m_frame = std::move(content);
}

void ViewServer::publish_stats(std::string json) {
    auto content = std::make_shared<const std::string>(std::move(json));
    std::scoped_lock hold(m_lock);
    m_stats = std::move(content);
}

std::vector<ViewCommand> ViewServer::take_commands() {
    std::vector<ViewCommand> taken;
    std::scoped_lock hold(m_lock);
    taken.swap(m_commands);
    return taken;
}

std::uint64_t ViewServer::refused() const {
    std::scoped_lock hold(m_lock);
    return m_refused;
}

}  // namespace spindle::app
