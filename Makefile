# The two commands of the README: `make demo` and `make test`. Both set up what is missing first.
# `make python` installs the Python package into .venv (without running the tests).
BUILD ?= build
JOBS ?= $(shell nproc)
CMAKE_FLAGS ?= -DCMAKE_BUILD_TYPE=Release
# cmake --build runs make again: no "Entering/Leaving directory" lines from the nested makes.
MAKEFLAGS += --no-print-directory

.PHONY: setup setup-python configure build demo test quality python bench gpu-pack fuzz libfuzz sanitize clean

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
	@./scripts/corpus_check.sh $(BUILD)
	@./scripts/blender_check.sh

# The full third-party corpus (~40 min to render the first time) and its quality tables
# (docs/quality.md, "Other renderers' output").
quality: build setup-python
	@python3 scripts/corpus/render.py --full
	@python3 scripts/corpus/cli_quality.py --corpus out/corpus/full --atrous $(BUILD)/atrous --json out/corpus/full/cli_quality.json
	@.venv/bin/python -m atrous.eval corpus --corpus out/corpus/full --crops

python: setup-python
	@JOBS=$(JOBS) ./scripts/python_install.sh

bench: build
	@./scripts/bench.sh $(BUILD)

# The GPU check's pack (build-gpu/pack/: sm_90 binaries, their Debian libraries, OIDN), for a session
# lent a GPU machine; then scripts/gpu-check.sh --dry-run prints the run invocation (docs/benchmarks.md, "GPU").
gpu-pack:
	@JOBS=$(JOBS) ./scripts/gpu-pack.sh

# The fuzz harnesses at full size (docs/reliability.md): the generator harness (FUZZ_CASES CLI cases
# plus a sixth as many Python-binding cases, seeded (FUZZ_SEED) and reproducible; `make test` runs
# its CI subset), then every libFuzzer target of the input readers for FUZZ_SECONDS each, JOBS at a
# time (scripts/libfuzz.sh: clang build in build-fuzz/, findings kept in out/libfuzz/; .ci/run runs
# each for 20 s). `make libfuzz` runs the libFuzzer targets alone.
FUZZ_CASES ?= 2000
FUZZ_SEED ?= 1
FUZZ_SECONDS ?= 600
fuzz: build setup-python
	@JOBS=$(JOBS) ./scripts/python_install.sh
	@python3 tests/fuzz/fuzz.py --cli $(BUILD)/atrous --cases $(FUZZ_CASES) --seed $(FUZZ_SEED) --jobs $(JOBS)
	@./scripts/libfuzz.sh --seconds $(FUZZ_SECONDS) --jobs $(JOBS)

libfuzz: setup
	@./scripts/libfuzz.sh --seconds $(FUZZ_SECONDS) --jobs $(JOBS)

# AddressSanitizer + UBSan build in build-asan/: the ctest suite and the fuzz CI subset (docs/reliability.md).
sanitize: setup
	@JOBS=$(JOBS) ./scripts/sanitize.sh build-asan

clean:
	rm -rf $(BUILD) $(BUILD).configure.log out

# The learned filter (docs/learned.md): its training venv (.venv-train), the dataset (out/train/data,
# resumable), the library's prepared planes (out/train/prep, through the atrous module in .venv) and
# the training run (out/train/run, then the fine-tunings out/train/run_ft, run_clean and run_lux, all resumable),
# which regenerates src/filters/learned_weights_default.cpp.
# Within 2 hours from nothing on 2 cores: TRAIN_MINUTES of training. `train-smoke`: a few scenes and steps.
TRAIN_BUILD ?= build-learn
TRAIN_STEPS ?= 4000
TRAIN_MINUTES ?= 60
# Phase 2: fine-tuning with the `noem` images too (variance and emission withheld) and a quarter of the
# crops from the corpus's training split (docs/learned.md). Both train the MLP alone (version 3's network;
# the built-in weights). `make train-context` then adds the context branch (version 4) to phase 2's weights
# and fine-tunes both (docs/learned.md, "Version 4"; measured, not built in).
TRAIN_FT_STEPS ?= 2000
TRAIN_FT_MINUTES ?= 25
# Phase 3 (2026-12-04): near-clean inputs too (64 spp) and a loss on each crop's root relMSE, so that the filter
# stops smoothing what is already clean (a sequence's temporal average, 16-spp stills); exports the built-in weights.
TRAIN_CLEAN_STEPS ?= 1500
TRAIN_CLEAN_MINUTES ?= 20
TRAIN_CLEAN_LOSS ?= sqrt
# Phase 4 (2026-12-04): phase 3's settings at half the learning rate, with the corpus's training split grown by 16
# LuxCore scenes (scripts/corpus/luxcore_train.py) and drawn for 30% of the crops; exports the built-in weights.
TRAIN_LUX_STEPS ?= 800
TRAIN_LUX_MINUTES ?= 10
TRAIN_CTX_STEPS ?= 1500
TRAIN_CTX_MINUTES ?= 30
.PHONY: train train-smoke
train: python
	@./scripts/train/setup.sh
	@cmake -S . -B $(TRAIN_BUILD) -DCMAKE_BUILD_TYPE=Release -DATROUS_ENABLE_CUDA=OFF > /dev/null
	@cmake --build $(TRAIN_BUILD) -j $(JOBS) --target atrous
	@.venv-train/bin/python scripts/train/dataset.py --atrous $(TRAIN_BUILD)/atrous --scenes 160 --test-scenes 16
	@.venv/bin/python scripts/train/prepare.py --splits train test corpus_train
	@# Where the corpus's test stills are rendered (make quality), --eval also reports them (never trained on).
	@if [ -d out/corpus/full ] && [ -x .venv-corpus/bin/python ]; then .venv-corpus/bin/python scripts/corpus/train_export.py --test --atrous $(TRAIN_BUILD)/atrous \
	  && .venv/bin/python scripts/train/prepare.py --splits corpus_test --variants est; fi
	@.venv-train/bin/python scripts/train/train.py --variants given est --steps $(TRAIN_STEPS) --minutes $(TRAIN_MINUTES) \
	  --eval --no-context
	@.venv-train/bin/python scripts/train/train.py --out out/train/run_ft --init out/train/run/weights.bin --lr 1e-3 \
	  --corpus-share 0.25 --steps $(TRAIN_FT_STEPS) --minutes $(TRAIN_FT_MINUTES) --eval --no-context
	@.venv-train/bin/python scripts/train/train.py --out out/train/run_clean --init out/train/run_ft/weights.bin --lr 1e-3 \
	  --corpus-share 0.25 --spps 1 4 16 64 --loss $(TRAIN_CLEAN_LOSS) --steps $(TRAIN_CLEAN_STEPS) --minutes $(TRAIN_CLEAN_MINUTES) \
	  --eval --no-context
	@.venv-train/bin/python scripts/train/train.py --out out/train/run_lux --init out/train/run_clean/weights.bin --lr 5e-4 \
	  --corpus-share 0.3 --spps 1 4 16 64 --loss $(TRAIN_CLEAN_LOSS) --steps $(TRAIN_LUX_STEPS) --minutes $(TRAIN_LUX_MINUTES) \
	  --eval --export --no-context

# Version 4 (the context branch) from `make train`'s weights (or the built-in ones, out/train/v3.bin): whole
# 128² images, half of them from the corpus's training split; writes out/train/run_ctx/weights.bin.
.PHONY: train-context
train-context:
	@./scripts/train/setup.sh
	@test -f out/train/run_ft/weights.bin || { echo "train-context: run make train first (out/train/run_ft/weights.bin)"; exit 2; }
	@.venv-train/bin/python scripts/train/train.py --out out/train/run_ctx --init out/train/run_ft/weights.bin --lr 1e-3 \
	  --corpus-share 0.5 --crop 128 --variants given est noem --steps $(TRAIN_CTX_STEPS) --minutes $(TRAIN_CTX_MINUTES) --eval

train-smoke: python
	@./scripts/train/setup.sh
	@cmake -S . -B $(TRAIN_BUILD) -DCMAKE_BUILD_TYPE=Release -DATROUS_ENABLE_CUDA=OFF > /dev/null
	@cmake --build $(TRAIN_BUILD) -j $(JOBS) --target atrous
	@.venv-train/bin/python scripts/train/dataset.py --atrous $(TRAIN_BUILD)/atrous --out out/train-smoke --scenes 3 --test-scenes 1 --size 64
	@.venv/bin/python scripts/train/prepare.py --data out/train-smoke/data --out out/train-smoke/prep --splits train test
	@.venv-train/bin/python scripts/train/train.py --prep out/train-smoke/prep --out out/train-smoke/run --steps 100 --crop 48 --eval
	@.venv-train/bin/python -m pytest -q tests/python/test_learn.py
