# avsim: `make demo` and `make test` each set everything up on a fresh machine, then run.
SHELL := /bin/bash
PY ?= python3
VENV := .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed
PYTEST_ARGS ?=

.PHONY: assets setup demo test test-quick acceptance fuzz lint golden bench soak campaign clean

# The virtual environment with the pinned dependencies (pyproject.toml), installed once.
$(STAMP): pyproject.toml
	@command -v $(PY) >/dev/null || { echo "need $(PY) (>= 3.11)"; exit 1; }
	test -d $(VENV) || $(PY) -m venv $(VENV)
	@dpkg -s mesa-vulkan-drivers >/dev/null 2>&1 || { \
		if command -v apt-get >/dev/null && [ "$$(id -u)" = 0 ]; then \
			apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq \
				mesa-vulkan-drivers >/dev/null || echo "note: installing mesa-vulkan-drivers failed"; \
		else echo "note: no mesa-vulkan-drivers (needs root + apt-get): avsim snapshot unavailable"; fi; }
	$(BIN)/pip install --quiet --upgrade pip
	$(BIN)/pip install --quiet -e '.[dev,ray]'
	$(BIN)/python -c "import avsim.deps as d; d.check()"
	touch $(STAMP)

setup: $(STAMP)

demo: $(STAMP)
	$(BIN)/avsim run normal_driving --out runs/normal_driving.rrd --json runs/normal_driving.json \
		--plot runs/normal_driving.png
	$(BIN)/avsim run decs_route --out runs/decs_route.rrd --json runs/decs_route.json \
		--plot runs/decs_route.png

lint: $(STAMP)
	$(BIN)/ruff check .
	$(BIN)/mypy

test: lint
	$(BIN)/pytest -n 2 --dist loadfile --no-loadscope-reorder -m "not acceptance" --durations=25 $(PYTEST_ARGS)

test-quick: lint
	$(BIN)/pytest -n 2 --dist loadfile --no-loadscope-reorder -m "not slow" $(PYTEST_ARGS)

# The acceptance set (scenarios/acceptance: Euro NCAP, UN R157, ISO 22179 grids), one test
# per run, each asserting its situation happened and its verdicts, and the esmini
# conformance runs of every permutation of a distribution file but the first; too long for
# `make test`.
acceptance: $(STAMP)
	$(BIN)/pytest -n 2 --dist load -m acceptance tests/scenarios tests/conformance $(PYTEST_ARGS)

# The fuzzers (tests marked `fuzz`) with many more inputs than `make test` tries, on a fresh
# seed each time unless AVSIM_FUZZ_SEED is given (a failure prints the seed to replay).
FUZZ_EXAMPLES ?= 3000
fuzz: $(STAMP)
	seed=$${AVSIM_FUZZ_SEED:-$$RANDOM}; echo "make fuzz: seed $$seed"; \
	AVSIM_FUZZ_EXAMPLES=$(FUZZ_EXAMPLES) AVSIM_FUZZ_SEED=$$seed $(BIN)/pytest -n 2 -m fuzz \
		-p no:cacheprovider --hypothesis-seed=$$seed tests $(PYTEST_ARGS)

# Rewrite the golden results (tests/scenarios/golden/) from the scenario tests' own runs: only
# for a change meant to alter behaviour, whose commit says which and why.
golden: $(STAMP)
	AVSIM_GOLDEN=write $(BIN)/pytest -n 2 --dist loadfile tests/scenarios -k golden -q

bench: $(STAMP)
	$(BIN)/python -m bench.bench_rtf
	$(BIN)/python -m bench.bench_components
	$(BIN)/python -m bench.bench_sensing
	$(BIN)/python -m bench.bench_stages
	$(BIN)/python -m bench.bench_batch
	$(BIN)/python -m bench.bench_campaign
	$(BIN)/python -m bench.bench_load

# An hour of simulated time on a town loop per profile (none, fast): memory, recording size
# and real-time factor over time (about 50 minutes here).
soak: $(STAMP)
	$(BIN)/python -m bench.bench_soak

# The scenario campaigns (scenarios/campaigns/*.yaml, docs/cli.md "Campaigns"): CAMPAIGN_N
# runs drawn from each family with a fixed seed (12 x 170 = 2,040 runs), default sensors and
# the consumer receiver, into runs/campaign_all; stopped, it resumes where it was.
CAMPAIGN_N ?= 170
CAMPAIGN_SEED ?= 1
campaign: $(STAMP)
	$(BIN)/avsim campaign scenarios/campaigns/*.yaml --n $(CAMPAIGN_N) --seed $(CAMPAIGN_SEED) \
		--profile default --resume --out runs/campaign_all $(CAMPAIGN_ARGS)

clean:
	rm -rf runs .pytest_cache .mypy_cache .ruff_cache

# The bodies' shapes as OBJ + MTL files (assets/shapes/), made from world/actors/shapes/; a
# test checks that the committed files are exactly what the code makes.
assets: $(STAMP)
	$(BIN)/python -m world.actors.shapes.export assets/shapes
