// The spindle program end to end: run with every layout (summary, trace JSON naming
// the stages, CSV record), bench's one line, scenes, help, and bad arguments giving a
// message and a non-zero exit code. SPINDLE_PROGRAM is the built binary.
#include <gtest/gtest.h>

#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace {

namespace fs = std::filesystem;

const fs::path kSource = SPINDLE_SOURCE_DIR;

struct Result {
    int exit_code = -1;
    std::string output;
};

// Runs `spindle ARGS` through the shell; captures stdout, and stderr too unless
// stdout_only. The shell quotes are the caller's.
Result spindle(const std::string& args, bool stdout_only = false, const std::string& cwd = "") {
    std::string command = std::string("'") + SPINDLE_PROGRAM + "' " + args + (stdout_only ? " 2>/dev/null" : " 2>&1");
    if (!cwd.empty()) command = "cd '" + cwd + "' && " + command;
    Result r;
    std::FILE* pipe = ::popen(command.c_str(), "r");
    if (!pipe) return r;
    char buffer[4096];
    std::size_t n;
    while ((n = std::fread(buffer, 1, sizeof buffer, pipe)) > 0) r.output.append(buffer, n);
    const int status = ::pclose(pipe);
    r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    return r;
}

std::string read_file(const fs::path& path) {
    std::ifstream in(path);
    std::stringstream text;
    text << in.rdbuf();
    return text.str();
}

fs::path temp_path(const std::string& name) {
    return fs::temp_directory_path() / ("spindle_program_test_" + std::to_string(::getpid()) + "_" + name);
}

// A strict JSON syntax check (RFC 8259), enough to know a trace file loads.
class JsonChecker {
public:
    explicit JsonChecker(const std::string& text) : m_text(text) {}
    bool valid() {
        skip();
        if (!value()) return false;
        skip();
        return m_pos == m_text.size();
    }

private:
    bool value() {
        skip();
        if (m_pos >= m_text.size()) return false;
        const char c = m_text[m_pos];
        if (c == '{') return container('}', true);
        if (c == '[') return container(']', false);
        if (c == '"') return string();
        if (literal("true") || literal("false") || literal("null")) return true;
        return number();
    }
    bool container(char close, bool object) {
        ++m_pos;
        skip();
        if (peek(close)) return ++m_pos, true;
        while (true) {
            skip();
            if (object) {
                if (!string()) return false;
                skip();
                if (!peek(':')) return false;
                ++m_pos;
            }
            if (!value()) return false;
            skip();
            if (peek(close)) return ++m_pos, true;
            if (!peek(',')) return false;
            ++m_pos;
        }
    }
    bool string() {
        if (!peek('"')) return false;
        for (++m_pos; m_pos < m_text.size(); ++m_pos) {
            const char c = m_text[m_pos];
            if (c == '"') return ++m_pos, true;
            if (static_cast<unsigned char>(c) < 0x20) return false;
            if (c == '\\') ++m_pos;
        }
        return false;
    }
    bool number() {
        const std::size_t start = m_pos;
        if (peek('-')) ++m_pos;
        while (m_pos < m_text.size() && (std::isdigit(static_cast<unsigned char>(m_text[m_pos])) ||
                                         m_text[m_pos] == '.' || m_text[m_pos] == 'e' || m_text[m_pos] == 'E' ||
                                         m_text[m_pos] == '+' || m_text[m_pos] == '-')) {
            ++m_pos;
        }
        return m_pos > start && std::isdigit(static_cast<unsigned char>(m_text[m_pos - 1]));
    }
    bool literal(const char* word) {
        const std::string w(word);
        if (m_text.compare(m_pos, w.size(), w) != 0) return false;
        m_pos += w.size();
        return true;
    }
    bool peek(char c) const { return m_pos < m_text.size() && m_text[m_pos] == c; }
    void skip() {
        while (m_pos < m_text.size() && std::isspace(static_cast<unsigned char>(m_text[m_pos]))) ++m_pos;
    }

    const std::string& m_text;
    std::size_t m_pos = 0;
};

void expect_contains(const std::string& text, const std::string& what) {
    EXPECT_NE(text.find(what), std::string::npos) << "missing '" << what << "' in:\n" << text;
}

std::vector<std::string> words(const std::string& line) {
    std::istringstream in(line);
    std::vector<std::string> out;
    for (std::string w; in >> w;) out.push_back(w);
    return out;
}

// The words of the output line that starts with `first` (empty if none).
std::vector<std::string> line_starting_with(const std::string& text, const std::string& first) {
    std::istringstream in(text);
    for (std::string line; std::getline(in, line);) {
        const std::vector<std::string> w = words(line);
        if (!w.empty() && w[0] == first) return w;
    }
    return {};
}

bool all_of_chars(const std::string& s, const char* allowed) {
    return !s.empty() && s.find_first_not_of(allowed) == std::string::npos;
}

TEST(SpindleProgram, JsonChecker_TellsValidFromBroken) {
    EXPECT_TRUE(JsonChecker(R"({"traceEvents":[{"name":"a","ts":1.5,"dur":-2e3,"x":[true,null]}]})").valid());
    EXPECT_FALSE(JsonChecker(R"({"traceEvents":[{"name":"a",}]})").valid());
    EXPECT_FALSE(JsonChecker(R"({"traceEvents":[)").valid());
}

TEST(SpindleProgram, RunWithEveryLayout_PrintsSummaryAndWritesTraceAndRecord) {
    std::vector<fs::path> layouts;
    for (const auto& entry : fs::directory_iterator(kSource / "configs" / "layouts")) {
        if (entry.path().extension() == ".toml") layouts.push_back(entry.path());
    }
    ASSERT_GE(layouts.size(), 4u);
    for (const fs::path& layout : layouts) {
        SCOPED_TRACE(layout.string());
        const fs::path trace = temp_path(layout.stem().string() + ".json");
        const fs::path record = temp_path(layout.stem().string() + ".csv");
        const Result r = spindle("run stack --seconds 1 --layout '" + layout.string() + "' --trace '" +
                                 trace.string() + "' --record '" + record.string() + "'");
        ASSERT_EQ(r.exit_code, 0) << r.output;
        expect_contains(r.output, "summary: scene stack, layout " + layout.stem().string());
        expect_contains(r.output, "smoothness");
        expect_contains(r.output, "motion lock");
        expect_contains(r.output, "dropped");

        const std::string json = read_file(trace);
        EXPECT_TRUE(JsonChecker(json).valid()) << "trace is not valid JSON";
        expect_contains(json, "\"traceEvents\"");
        for (const char* stage :
             {"ApplyWrites", "Broadphase", "Narrowphase", "Islands", "Solver", "Record", "FlipReadBuffers", "Frame"}) {
            expect_contains(json, std::string("\"name\":\"") + stage + "\",\"ph\":\"X\"");
        }

        const std::string csv = read_file(record);
        ASSERT_EQ(csv.rfind("frame,time,body,px,py,pz,qw,qx,qy,qz,vx,vy,vz\n", 0), 0u);
        const auto rows = static_cast<std::size_t>(std::count(csv.begin(), csv.end(), '\n')) - 1;
        EXPECT_GT(rows, 21u * 30u);   // stack: 21 bodies, about 60 frames in a second
        EXPECT_EQ(rows % 21u, 0u);    // whole frames only
        fs::remove(trace);
        fs::remove(record);
    }
}

TEST(SpindleProgram, RunWithoutArguments_PlaysTheDefaultSceneFromAnyDirectory) {
    // The default is 5 s; --seconds keeps the test short, but the scene comes from the
    // binary (run from / where no configs/ exists).
    const Result r = spindle("run --seconds 1", false, "/");
    ASSERT_EQ(r.exit_code, 0) << r.output;
    expect_contains(r.output, "scene pile (configs/scenes/pile.toml): 192 dynamic + 1 other bodies");
    expect_contains(r.output, "summary: scene pile, layout native");
    expect_contains(r.output, "ApplyWrites");
    // Not a terminal: progress comes as plain lines, no carriage returns.
    EXPECT_EQ(r.output.find('\r'), std::string::npos);
}

TEST(SpindleProgram, RunASceneFile) {
    const fs::path file = temp_path("ball.toml");
    std::ofstream(file) << "description = \"one ball\"\n[[body]]\nshape = { sphere = 0.5 }\nposition = [0, 10, 0]\n";
    const Result r = spindle("run '" + file.string() + "' --seconds 0.3 --render-hz 30 --idle sleep");
    fs::remove(file);
    ASSERT_EQ(r.exit_code, 0) << r.output;
    expect_contains(r.output, "1 dynamic + 0 other bodies; one ball");
    expect_contains(r.output, "idle sleep");
}

TEST(SpindleProgram, BenchPyramid_PrintsOneLine) {
    const Result r = spindle("bench pyramid --steps 5", true);
    ASSERT_EQ(r.exit_code, 0) << r.output;
    // scene=pyramid bodies=1240 threads=1 steps=5 steps_per_s=X top_y=Y hash=0x<16 hex digits>\n
    ASSERT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << r.output;
    ASSERT_EQ(r.output.back(), '\n');
    const std::vector<std::string> w = words(r.output);
    ASSERT_EQ(w.size(), 7u) << r.output;
    EXPECT_EQ(w[0], "scene=pyramid");
    EXPECT_EQ(w[1], "bodies=1240");
    EXPECT_EQ(w[2], "threads=1");
    EXPECT_EQ(w[3], "steps=5");
    EXPECT_EQ(w[4].rfind("steps_per_s=", 0), 0u);
    EXPECT_TRUE(all_of_chars(w[4].substr(12), "0123456789.")) << w[4];
    EXPECT_EQ(w[5].rfind("top_y=", 0), 0u);
    EXPECT_TRUE(all_of_chars(w[5].substr(6), "-0123456789.")) << w[5];
    EXPECT_EQ(w[6].rfind("hash=0x", 0), 0u);
    EXPECT_EQ(w[6].size(), 7u + 16u) << w[6];
    EXPECT_TRUE(all_of_chars(w[6].substr(7), "0123456789abcdef")) << w[6];

    const Result substeps = spindle("bench stack --steps 3 --substeps 2 --threads 1", true);
    ASSERT_EQ(substeps.exit_code, 0) << substeps.output;
    expect_contains(substeps.output, "scene=stack bodies=20 threads=1 steps=3 ");
}

TEST(SpindleProgram, BenchStages_PrintsMillisecondsPerStage) {
    const Result r = spindle("bench stack --steps 20 --stages", true);
    ASSERT_EQ(r.exit_code, 0) << r.output;
    ASSERT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 2) << r.output;
    const std::string second = r.output.substr(r.output.find('\n') + 1);
    const std::vector<std::string> w = words(second);
    ASSERT_GE(w.size(), 4u) << second;
    EXPECT_EQ(w[0], "stages_ms");
    bool solver = false;
    for (std::size_t i = 1; i < w.size(); ++i) {
        const std::size_t eq = w[i].find('=');
        ASSERT_NE(eq, std::string::npos) << w[i];
        const double ms = std::stod(w[i].substr(eq + 1));
        EXPECT_GT(ms, 0.0) << w[i];  // only stages that took time are listed
        if (w[i].rfind("Solver=", 0) == 0) solver = true;
    }
    EXPECT_TRUE(solver) << second;
    const Result bad = spindle("bench stack --stages=yes");
    EXPECT_EQ(bad.exit_code, 2);
    expect_contains(bad.output, "--stages: takes no value");
}

// Same scene, same steps: the same state, bit for bit, whatever the worker count.
TEST(SpindleProgram, BenchHash_IsTheSameForOneAndTwoThreads) {
    const Result one = spindle("bench dominoes --steps 60 --threads 1", true);
    const Result two = spindle("bench dominoes --steps 60 --threads 2", true);
    ASSERT_EQ(one.exit_code, 0) << one.output;
    ASSERT_EQ(two.exit_code, 0) << two.output;
    expect_contains(two.output, " threads=2 ");
    const auto hash = [](const std::string& s) { return s.substr(s.find("hash=")); };
    EXPECT_EQ(hash(one.output), hash(two.output)) << one.output << two.output;
}

TEST(SpindleProgram, Scenes_ListsEveryBuiltInSceneWithItsBodyCount) {
    const Result r = spindle("scenes");
    ASSERT_EQ(r.exit_code, 0) << r.output;
    for (const auto& entry : fs::directory_iterator(kSource / "configs" / "scenes")) {
        if (entry.path().extension() == ".toml") expect_contains(r.output, entry.path().stem().string() + " ");
    }
    // name, dynamic bodies, other bodies, description
    for (const auto& [scene, dynamic] :
         std::vector<std::pair<std::string, std::string>>{{"pyramid", "1240"}, {"many_pyramids", "10780"}, {"stack", "20"}}) {
        const std::vector<std::string> w = line_starting_with(r.output, scene);
        ASSERT_GE(w.size(), 3u) << scene << " not listed in\n" << r.output;
        EXPECT_EQ(w[1], dynamic) << scene;
        EXPECT_EQ(w[2], "1") << scene;
    }
}

TEST(SpindleProgram, Help_ForEveryCommand) {
    for (const char* args : {"--help", "help", "run --help", "bench --help", "scenes --help", "layout --help"}) {
        SCOPED_TRACE(args);
        const Result r = spindle(args);
        EXPECT_EQ(r.exit_code, 0) << r.output;
        expect_contains(r.output, "usage: spindle");
    }
    const Result layout = spindle("layout '" + (kSource / "configs" / "layouts" / "xbox360.toml").string() + "'");
    EXPECT_EQ(layout.exit_code, 0) << layout.output;
    expect_contains(layout.output, "layout xbox360");
}

TEST(SpindleProgram, BadArguments_FailWithAMessage) {
    const fs::path bad = temp_path("bad.toml");
    std::ofstream(bad) << "[[body]]\nshape = { sphere = 1 }\nfriction = \"high\"\n";
    struct Case {
        std::string args;
        int exit_code;
        std::string message;
    };
    const std::vector<Case> cases = {
        {"frob", 2, "unknown command 'frob'"},
        {"run nope", 2, "unknown scene 'nope' (built-in scenes: "},
        {"run --bogus", 2, "unknown option '--bogus'"},
        {"run --seconds", 2, "--seconds: 1 required FLOAT missing"},
        {"run --seconds abc", 2, "--seconds: expected a number, got 'abc'"},
        {"run --seconds -1", 2, "--seconds: expected a number in"},
        {"run --render-hz 0", 2, "--render-hz: expected a number in"},
        {"run --idle nap", 2, "--idle: nap not in {poll,spin,sleep}"},
        {"run stack extra", 2, "unexpected argument 'extra'"},
        {"run --layout /nonexistent/layout.toml", 1, "/nonexistent/layout.toml: cannot open layout file"},
        {"run --trace /nonexistent/dir/trace.json --seconds 0.1", 1, "cannot write the trace file"},
        {"run '" + bad.string() + "'", 1, bad.string() + ":3:12: body.friction: expected a number, got a string"},
        {"bench", 2, "SCENE is required"},
        {"bench pyramid --steps x", 2, "--steps: expected an integer, got 'x'"},
        {"bench pyramid --steps 0", 2, "--steps: expected an integer in [1, "},
        {"bench pyramid --threads 1.5", 2, "--threads: expected an integer, got '1.5'"},
        {"bench pyramid --substeps", 2, "--substeps: 1 required INT missing"},
        {"bench /nonexistent/scene.toml", 1, "/nonexistent/scene.toml: cannot open scene file"},
        {"scenes extra", 2, "unexpected argument 'extra'"},
        {"layout", 2, "FILE is required"},
        {"layout '" + bad.string() + "'", 1, "unknown key"},
    };
    for (const Case& c : cases) {
        SCOPED_TRACE(c.args);
        const Result r = spindle(c.args);
        EXPECT_EQ(r.exit_code, c.exit_code) << r.output;
        expect_contains(r.output, c.message);
    }
    fs::remove(bad);
}

}  // namespace
