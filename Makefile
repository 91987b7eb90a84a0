# 3-RPS elastodynamics: analytical substructure model validated against a 3D solid FEM.
#   make          set up (first time) and run the validation of the default scene into out/
#   make campaign correlate and identify the test campaign (CAMPAIGN=...) into out/
#   make test     set up (first time) and run the test suite
#   make lint     the linter (ruff) and the type checker (mypy), as CI runs them
#   make verify   the solid FEM against published benchmarks (pytest -m verification)
#   make bench    timing benchmarks (medians of repeated runs) into bench/ (kept across runs)
#   make report   rebuild out/report.html and out/report.pdf from out/results.json
#   make design   a design study (DESIGN=designs/3prs-head.toml) into design-out/
#   make clean-cache  empty the result, mesh, timing and figure caches (out/ stays)
#   make clean    remove outputs and caches

SCENE  ?= scenes/paper.toml
CAMPAIGN ?= campaigns/actuator-legs/campaign.toml
DESIGN ?= designs/3prs-head.toml
VENV   ?= .venv
PYTHON := $(VENV)/bin/python
STAMP  := $(VENV)/.installed
export MPLBACKEND := Agg
export PYVISTA_OFF_SCREEN := true
export OPENBLAS_NUM_THREADS ?= 1

.DEFAULT_GOAL := run
.PHONY: run campaign setup test fuzz scenes verify lint bench report readme readme-timings docs clean clean-cache update-baselines design

$(STAMP): pyproject.toml
	@mkdir -p bench && date +%s.%N > bench/.setup-begin
	python3 -m venv $(VENV)
	$(PYTHON) -m pip install --quiet --upgrade pip
	$(PYTHON) -m pip install --quiet -e '.[fem,report,test,modal-test,fast]'
	touch $@
	@$(PYTHON) -m pipeline.make_timing setup-end

setup: $(STAMP)

# `make` and `make test` time themselves (pipeline/make_timing.py: bench/timings.jsonl, the
# README's timings block through `make readme-timings`)
run: $(STAMP)
	@$(PYTHON) -m pipeline.make_timing begin make
	$(PYTHON) -m rps validate --scene $(SCENE) --out out --no-report
	@# the whole chain in one report, written even when the campaign fails (make then fails)
	@status=0; $(MAKE) --no-print-directory campaign || status=$$?; \
	  $(PYTHON) -m rps report --results out/results.json --out out && exit $$status
	@$(PYTHON) -m pipeline.make_timing end make

# the example test campaign (CAMPAIGN): correlation and identification into out/
campaign: $(STAMP)
	$(PYTHON) -m rps correlate --campaign $(CAMPAIGN) --out out/correlation
	$(PYTHON) -m rps identify --campaign $(CAMPAIGN) --out out/identification

# two workers (pytest-xdist): the suite's heavy tests are single-threaded (one BLAS thread)
test: $(STAMP)
	@$(PYTHON) -m pipeline.make_timing begin test
	$(PYTHON) -m pytest -n 2
	@$(PYTHON) -m pipeline.make_timing end test

# random plausible machines end to end (tests/test_fuzz_machines.py); RPS_FUZZ=slow for more
fuzz: $(STAMP)
	$(PYTHON) -m pytest -n 2 -m fuzz

# every shipped scene but the paper's at CI size against its golden (tests/test_scenes.py)
scenes: $(STAMP)
	$(PYTHON) -m pytest -n 2 -m scenes

verify: $(STAMP)
	$(PYTHON) -m pytest -m verification

lint: $(STAMP)
	$(PYTHON) -m ruff check .
	$(PYTHON) -m mypy

bench: $(STAMP)
	$(PYTHON) -m pipeline.bench --scene $(SCENE)

report: $(STAMP)
	$(PYTHON) -m rps report --results out/results.json --out out

readme: $(STAMP)
	$(PYTHON) -m rps readme --results out/results.json

# the README's timings block from the newest `make` and `make test` records of this machine
readme-timings: $(STAMP)
	$(PYTHON) -m rps readme --timings

docs: $(STAMP)
	$(PYTHON) -m rps scene-docs

design: $(STAMP)
	$(PYTHON) -m rps design --design $(DESIGN) --report design-out

update-baselines: $(STAMP)
	$(PYTHON) -m rps update-baselines --scene $(SCENE)

clean-cache: $(STAMP)
	$(PYTHON) -m rps cache clear

clean:
	rm -rf out .out.staging-* .out.previous-* .out.lock out.partial design-out .design-out.* .cache .pytest_cache .hypothesis
