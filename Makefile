# Spindle quick start:  make run    (set up, build the program in Release, run the default scene)
#                       make test   (set up, check formatting, build, run every test: Release, ASan+UBSan, TSan)
#                       make format (rewrite the C++ sources per .clang-format)
#                       make tidy   (clang-tidy per .clang-tidy over the sources; slow, not part of make test)
JOBS ?= 2
BUILD ?= build
CMAKE_COMMON = -DCMAKE_EXPORT_COMPILE_COMMANDS=ON
# Sanitizer builds: optimised a little so Eigen-heavy tests stay quick; asserts on; line
# tables only (-g1: the reports' file:line, not locals), far cheaper to compile than -g.
SAN_FLAGS = -DCMAKE_BUILD_TYPE=Debug -DCMAKE_CXX_FLAGS_DEBUG="-O1 -g1" -DSPINDLE_BUILD_BENCH=OFF -DSPINDLE_UNITY_ENGINE=ON
# The C++ sources under version control, at any depth below these folders (generated and
# build files are not tracked); a folder that does not exist matches nothing.
SOURCE_DIRS = engine scheduler platform scene apps tests bench
CXX_SOURCES = git ls-files -- $(foreach d,$(SOURCE_DIRS),'$(d)/*.cpp' '$(d)/*.hpp')
CLANG_FORMAT ?= clang-format
CLANG_TIDY ?= clang-tidy

.PHONY: setup setup-test configure-release release run test test-release test-asan test-tsan format format-check tidy bench accuracy clean

setup:
	@bash scripts/setup.sh

# make test's packages besides setup's (a headless browser for the view page's test).
setup-test:
	@bash scripts/setup.sh --test

configure-release: setup
	@cmake -S . -B $(BUILD)/release -DCMAKE_BUILD_TYPE=Release $(CMAKE_COMMON) >/dev/null

release: configure-release
	@cmake --build $(BUILD)/release -j$(JOBS)

# Only the program and what it links: no test or benchmark is built before the scene shows.
run: configure-release
	@cmake --build $(BUILD)/release -j$(JOBS) --target spindle
	./$(BUILD)/release/apps/spindle run

test: format-check test-release test-asan test-tsan

# Rewrites every C++ source in place per .clang-format.
format: setup
	@$(CXX_SOURCES) | xargs -r $(CLANG_FORMAT) -i

# Fails, naming the lines, if any C++ source differs from what `make format` writes.
format-check: setup
	@$(CXX_SOURCES) | xargs -r $(CLANG_FORMAT) --dry-run --Werror || \
		{ echo "format-check: run 'make format'" >&2; exit 1; }

# clang-tidy per .clang-tidy over the .cpp files (their project headers come with them),
# using the Release build's compile_commands.json. The compile commands are GCC's: clang
# ignores the warning flags it does not know, and reports its warnings without -Werror.
tidy: configure-release
	@git ls-files -- $(foreach d,$(SOURCE_DIRS),'$(d)/*.cpp') | xargs -r -P$(JOBS) -n1 $(CLANG_TIDY) -p $(BUILD)/release --quiet \
		--extra-arg=-Wno-unknown-warning-option --extra-arg=-Wno-error

# Builds what the Release ctest runs (tests_all: the suites and the spindle program), not
# the benchmark programs, which no test runs (`make release` and `make bench` build them).
test-release: setup-test configure-release
	@cmake --build $(BUILD)/release -j$(JOBS) --target tests_all
	cd $(BUILD)/release && ctest --output-on-failure -j$(JOBS)

test-asan: setup
	@cmake -S . -B $(BUILD)/asan -DSPINDLE_SANITIZE=address -DSPINDLE_VALIDATE_STATE=ON $(SAN_FLAGS) $(CMAKE_COMMON) >/dev/null
	@cmake --build $(BUILD)/asan -j$(JOBS) --target tests_engine tests_threaded
	cd $(BUILD)/asan && ctest --output-on-failure -j$(JOBS) -L "engine|threaded"

test-tsan: setup
	@cmake -S . -B $(BUILD)/tsan -DSPINDLE_SANITIZE=thread $(SAN_FLAGS) -DSPINDLE_BUILD_APPS=OFF $(CMAKE_COMMON) >/dev/null
	@cmake --build $(BUILD)/tsan -j$(JOBS) --target tests_threaded
	cd $(BUILD)/tsan && TSAN_OPTIONS="halt_on_error=1 second_deadlock_stack=1" ctest --output-on-failure -j$(JOBS) -L threaded

bench: release
	@for b in $(BUILD)/release/bench/*/bench_*; do [ -x "$$b" ] && "$$b" --benchmark_min_time=0.2; done

# Builds only bench_accuracy (not all of release) so a fresh clone finishes in minutes.
accuracy: configure-release
	@cmake --build $(BUILD)/release -j$(JOBS) --target bench_accuracy
	bash scripts/accuracy.sh $(BUILD)/release

clean:
	rm -rf $(BUILD)
