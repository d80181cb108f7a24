# The two commands of the README:
#   make replicate   set up .venv if needed, then run the full replication (snakemake -j2)
#   make test        set up .venv if needed, then lint and run the test suite
# (make test-fast: the quick tier, no lint and no test marked workflow, slurm or compile)
# Set-up needs only Python >= 3.11 with pip and venv, and access to PyPI.

PYTHON ?= python3
VENV ?= .venv
CORES ?= 2
BIN := $(VENV)/bin

# EMULATE=avx2: run any target as on an x86-64 CPU with AVX2 but no AVX-512 (numba compiles
# for znver3 with that model's own features, OpenBLAS runs its Haswell kernels, numpy's AVX-512
# loops are off): make replicate EMULATE=avx2 (docs/performance.md#without-avx-512)
ifeq ($(EMULATE),avx2)
export NUMBA_CPU_NAME := znver3
export NUMBA_CPU_FEATURES :=
export OPENBLAS_CORETYPE := Haswell
export NPY_DISABLE_CPU_FEATURES := X86_V4 AVX512_ICL AVX512_SPR
else ifneq ($(EMULATE),)
$(error EMULATE=$(EMULATE): the only emulation is avx2 (or leave EMULATE unset))
endif
PACKAGES := $(VENV)/.rsmhp-packages
STAMP := $(VENV)/.rsmhp-installed
# install into the venv with uv when it is there, else with pip: $(call INSTALL,args). uv
# compiles the bytecode as pip does (--compile-bytecode): without it, where Python writes no
# .pyc (PYTHONDONTWRITEBYTECODE, a read-only venv) every process, each job and each parse,
# compiles snakemake, pandas and scipy again (docs/performance.md, "Set-up")
INSTALL = if test -x $(BIN)/uv && $(BIN)/uv pip install --quiet --compile-bytecode \
	--python $(BIN)/python $(1); then :; else $(BIN)/python -m pip install --quiet $(1); fi

.PHONY: help replicate tune publish verify portability compare test test-fast lint setup clean

help:
	@echo "rsmhp: replication pipeline (RS-MHP vs NBO). Targets:"
	@echo "  make replicate [ARGS=...]  set up .venv if needed, run the full replication (snakemake -j$(CORES) ARGS)"
	@echo "  make tune [ARGS=...]       the protocol's tuning (tuning stream; not in replicate), then"
	@echo "                             copy results/tune/tuned.yaml to $(TUNED), its tables to $(TUNING_DIR)/"
	@echo "  make verify [ARGS=...]     run what is missing, compare every claim with paper/claims.json"
	@echo "  make compare PLUGIN_METHODS=a,b  new planners paired with the published reference (docs/compare.md)"
	@echo "  make portability [ARGS=...] rerun as on another CPU (numba generic, OpenBLAS Nehalem, no"
	@echo "                             numpy SIMD) elsewhere; compare with results/ and paper/claims.json"
	@echo "  make publish               update the tracked paper/ and README results from results/paper/"
	@echo "  make test                  set up, lint, run the test suite (what CI runs)"
	@echo "  make test-fast             the quick tier: no lint, no test marked workflow, slurm or compile"
	@echo "  make setup                 create .venv, install rsmhp[dev], compile every numba kernel (in parallel)"
	@echo "  make lint                  ruff, ruff format --check, snakefmt --check, snakemake --lint"
	@echo "  make clean                 delete results/ and .snakemake/"
	@echo "Variables: CORES=$(CORES) PYTHON=$(PYTHON) VENV=$(VENV) EMULATE=$(EMULATE) (avx2: as on a CPU without AVX-512)"
	@echo "Check a config overlay:  $(BIN)/python -m rsmhp.pipeline.config my.yaml"
	@echo "Rules and targets (snakemake --list-rules):"
	@test -x $(BIN)/snakemake && $(BIN)/snakemake --list-rules 2>/dev/null | sed 's/^/  /' || echo "  (run make setup first)"

# two steps: the packages (PACKAGES, what lint needs), then the compiled kernels (STAMP, what
# everything else needs); make test lints while the kernels compile
$(PACKAGES): pyproject.toml
	@$(PYTHON) -c 'import sys; sys.exit(0 if sys.version_info >= (3, 11) else "rsmhp needs Python >= 3.11, found " + sys.version.split()[0])'
	@test -x $(BIN)/python || $(PYTHON) -m venv $(VENV)
	@# uv (from PyPI, into the venv) resolves and installs the same releases as pip, in about
	@# 22 s against pip's 78 (docs/performance.md, "Set-up"); pip does it if uv fails
	$(BIN)/python -m pip install --quiet uv || true
	$(call INSTALL,-e '.[dev]')
	@touch $(PACKAGES)

$(STAMP): $(PACKAGES)
	@# compile every numba kernel once per machine, in parallel (on-disk cache; every job loads it)
	$(BIN)/python -m rsmhp.pipeline.warm --cores $(CORES)
	@touch $(STAMP)

setup: $(STAMP)

# extra snakemake flags: make replicate ARGS="--rerun-incomplete"
replicate: $(STAMP)
	$(BIN)/snakemake -j$(CORES) $(ARGS)

# the protocol's tuning on its own seed stream (not part of replicate): every candidate in closed
# loop and in an interleaved timing, the selection rule, and the tuned file copied to TUNED
# with the tuning tables beside it in TUNING_DIR (tracked: a new preregistration must follow
# before the next confirmatory run). The default is the third tuning's: config/tuned.yaml is
# the file the second preregistration names, and the published run depends on it.
TUNED ?= config/tuned_v3.yaml
TUNING_DIR ?= paper/tuning_v3
tune: $(STAMP)
	$(BIN)/snakemake -j$(CORES) tune $(ARGS)
	cp results/tune/tuned.yaml $(TUNED)
	mkdir -p $(TUNING_DIR)
	cp results/tune/selection.csv results/tune/candidates.csv results/tune/tuning.md results/tune/depth.md $(TUNING_DIR)/
	@echo "$(TUNED) and $(TUNING_DIR)/ written: write and commit a new preregistration before the confirmatory run"

# copy the report of results/ into the tracked paper/ (the only target that changes tracked files)
# copy the report, its claims (the reference of make verify) and the README's glance table,
# and add the run's verdicts to paper/history.csv (the fragility lines of later reports)
PUBLISHED := results/paper/replication.md results/paper/appendix.md results/paper/claims.json \
	results/paper/glance.md results/frontier/reference/frontier_confirm_runs.parquet \
	results/frontier/reference/frontier_confirm.json

publish: $(STAMP)
	$(BIN)/snakemake -j$(CORES) report frontier_reference $(ARGS)
	@for f in $(PUBLISHED); do test -f $$f || { echo "make publish: $$f is missing; nothing was copied" >&2; exit 1; }; done
	rm -rf paper/figures
	mkdir -p paper/figures
	cp results/paper/replication.md results/paper/appendix.md results/paper/claims.json paper/
	cp results/paper/figures/*.png paper/figures/
	$(BIN)/python -m rsmhp.report.readme splice README.md results/paper/glance.md
	$(BIN)/python -m rsmhp.report.history add results/paper/claims.json --kind implementation
	mkdir -p paper/reference
	cp results/frontier/reference/frontier_confirm_runs.parquet results/frontier/reference/frontier_confirm.json paper/reference/

# new planning methods (any registered family, e.g. from a plugin package) on the confirmatory
# design's scenarios, paired with the published reference paper/reference/ without rerunning
# it: make compare PLUGIN_METHODS=lhs_nt64 (comma-separated names); docs/compare.md
comma := ,
compare: $(STAMP)
	@test -n "$(PLUGIN_METHODS)" || { echo "make compare: give PLUGIN_METHODS=name[,name...]" >&2; exit 2; }
	$(BIN)/snakemake -j$(CORES) compare --config 'plugin_methods=[$(subst $(comma),$(comma) ,$(PLUGIN_METHODS))]' $(ARGS)

# compare a run with the committed reference paper/claims.json, claim by claim (runs what is
# missing first); fails if a verdict flips or a key number leaves its tolerance
verify: $(STAMP)
	$(BIN)/snakemake -j$(CORES) verify $(ARGS)

# portability drill: run what is missing natively, rerun the workflow emulating another CPU in a
# temporary directory (results/ is only read), compare table by table and claim by claim;
# writes results/portability/drill.md and drill.json; fails if a verdict differs or verify
# fails. ARGS go to the drill: make portability ARGS="--openblas-coretype Haswell --keep"
portability: $(STAMP)
	$(BIN)/python -m rsmhp.report.portability --cores $(CORES) $(ARGS)

lint: $(PACKAGES)
	$(BIN)/ruff check .
	$(BIN)/ruff format --check .
	$(BIN)/snakefmt --check .
	$(BIN)/snakemake --lint

# the template method plugin (examples/rsmhp-plugin-example), installed into the venv once: its
# family is then in the registry, so the conformance tests check it; its own tests run with ours
PLUGIN := examples/rsmhp-plugin-example
PLUGIN_STAMP := $(VENV)/.rsmhp-plugin-example-installed

$(PLUGIN_STAMP): $(PACKAGES) $(PLUGIN)/pyproject.toml
	$(call INSTALL,-e $(PLUGIN))
	@touch $(PLUGIN_STAMP)

# the suite on CORES pytest-xdist workers: a test file's tests on one worker (its module-scoped
# fixtures, the SLURM cluster among them, are made once), the longest first; the session's
# tiny runs are made once and shared by the workers (tests/conftest.py). Serially:
# $(BIN)/pytest tests
XDIST := -n $(CORES) --dist loadfile --no-loadscope-reorder
# lint (one process, about 20 s) runs beside the kernels' compile (whose second process ends
# first) and the tests, its output printed after theirs; make test fails if either fails (make
# then exits 2 whatever pytest's status, 5 when no test ran included: .ci/run fails on any
# non-zero status)
test: $(PLUGIN_STAMP)
	@log=$$(mktemp); $(MAKE) --no-print-directory -o $(PACKAGES) lint > $$log 2>&1 & lint=$$!; \
	if $(MAKE) --no-print-directory $(STAMP); then \
	$(BIN)/python -m pytest $(XDIST) --durations=25 tests $(PLUGIN)/tests; rc=$$?; \
	else rc=1; echo "make test: set-up failed (above)" >&2; fi; \
	wait $$lint; lint_rc=$$?; echo "--- make lint (beside the tests)"; cat $$log; rm -f $$log; \
	if [ $$lint_rc -ne 0 ]; then echo "make test: lint failed (above)" >&2; exit 1; fi; \
	exit $$rc

# the quick tier (tests/conftest.py): every test but those that run the workflow for real
# (workflow), on the local SLURM cluster (slurm) or compile numba kernels cold or for another
# CPU (compile); no lint. make test runs them all. On CORES pytest-xdist workers that take work
# from each other (no test of this tier shares anything across processes).
FAST := not workflow and not slurm and not compile
test-fast: $(STAMP) $(PLUGIN_STAMP)
	$(BIN)/python -m pytest -n $(CORES) --dist worksteal --durations=10 -m "$(FAST)" tests $(PLUGIN)/tests

clean:
	rm -rf results .snakemake
