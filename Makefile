# The two commands of the README: `make demo` and `make test`. Both set up what is missing first.
# `make python` installs the Python package into .venv (without running the tests).
BUILD ?= build
JOBS ?= $(shell nproc)
CMAKE_FLAGS ?= -DCMAKE_BUILD_TYPE=Release
# cmake --build runs make again: no "Entering/Leaving directory" lines from the nested makes.
MAKEFLAGS += --no-print-directory

.PHONY: setup setup-python configure build demo test python bench gpu-pack clean

setup:
	@./scripts/setup.sh

setup-python:
	@./scripts/setup.sh --python

configure: setup
	@cmake -S . -B $(BUILD) $(CMAKE_FLAGS) > $(BUILD).configure.log 2>&1 || (cat $(BUILD).configure.log; exit 1)

build: configure
	@cmake --build $(BUILD) -j $(JOBS)

# The demo needs the CLI only: no tests, benchmarks or Python packages.
demo: configure
	@cmake --build $(BUILD) -j $(JOBS) --target atrous
	@./scripts/demo.sh $(BUILD)

test: build setup-python
	@cd $(BUILD) && ctest --output-on-failure -j $(JOBS)
	@JOBS=$(JOBS) ./scripts/python_test.sh

python: setup-python
	@JOBS=$(JOBS) ./scripts/python_install.sh

bench: build
	@./scripts/bench.sh $(BUILD)

# The GPU check's pack (build-gpu/pack/: sm_90 binaries, their Debian libraries, OIDN), for a session
# lent a GPU machine; then scripts/gpu-check.sh --dry-run prints the run invocation (docs/benchmarks.md, "GPU").
gpu-pack:
	@JOBS=$(JOBS) ./scripts/gpu-pack.sh

clean:
	rm -rf $(BUILD) $(BUILD).configure.log out
