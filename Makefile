# rocklab: every target bootstraps .venv from a bare Python 3.11 (idempotent).
PYTHON ?= python3
VENV   := .venv
PY     := $(VENV)/bin/python
STAMP  := $(VENV)/.installed

.PHONY: test test-browser demo bench lint docs docs-serve install-user venv clean figures

venv: $(STAMP)

$(STAMP): pyproject.toml
	@test -x $(PY) || $(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --quiet --upgrade pip
	$(PY) -m pip install --quiet -e ".[test]"
	@touch $(STAMP)

# pytest exit code 5 (no tests collected) is a failure too. One worker per core (pytest-xdist), a
# test file to one worker so its module fixtures are built once, the heavy files first (HEAVY_FIRST in
# tests/conftest.py); TEST_WORKERS=0 runs in this process.
# With workers, numba's cache is filled first (tests/_numba_warm.py): in a fresh clone both workers
# compiled the Newmark and column kernels (about 63 of the suite's 1364 CPU-s twice).
TEST_WORKERS ?= auto
test: $(STAMP)
	$(if $(filter 0,$(TEST_WORKERS)),,$(PY) tests/_numba_warm.py)
	$(PY) -m pytest -q $(if $(filter 0,$(TEST_WORKERS)),,-n $(TEST_WORKERS) --dist loadfile --no-loadscope-reorder)

# real-browser tests: Debian's Chromium (installed here when root and apt allow) driven by
# Playwright from PyPI, pointed at that Chromium (no browser download). Skips, saying why,
# when Chromium cannot be installed; fails when a test fails.
test-browser: $(STAMP)
	@command -v chromium >/dev/null 2>&1 || { [ "$$(id -u)" = 0 ] && command -v apt-get >/dev/null 2>&1 && \
	  { DEBIAN_FRONTEND=noninteractive apt-get install -y -q chromium >/dev/null 2>&1 || \
	    { apt-get update -q >/dev/null 2>&1 && DEBIAN_FRONTEND=noninteractive apt-get install -y -q chromium >/dev/null 2>&1; }; }; } || true
	@if ! command -v chromium >/dev/null 2>&1; then \
	  echo "test-browser: SKIPPED: Chromium is not installed and could not be (needs root and Debian's apt)"; \
	else \
	  $(PY) -m pip install --quiet -e ".[browser]" && $(PY) -m pytest -q -p no:cacheprovider -m browser tests/browser; \
	fi

demo: $(STAMP)
	$(VENV)/bin/rocklab demo
	@echo "the commands are in $(VENV)/bin: 'source $(VENV)/bin/activate' (or 'make install-user'), then 'rerun demo_out/results/campaign.rrd'"

# rocklab and rerun on the user's PATH without activating .venv: symlinks in ~/.local/bin
BINDIR ?= $(HOME)/.local/bin
install-user: $(STAMP)
	@mkdir -p "$(BINDIR)"
	@for c in rocklab rerun; do ln -sf "$(abspath $(VENV))/bin/$$c" "$(BINDIR)/$$c" && echo "linked $(BINDIR)/$$c"; done
	@case ":$$PATH:" in *":$(BINDIR):"*) ;; *) echo "$(BINDIR) is not on your PATH: add 'export PATH=\"$(BINDIR):\$$PATH\"' to ~/.bashrc";; esac

lint: $(STAMP)
	$(PY) -m pip install --quiet -e ".[lint]"
	$(VENV)/bin/ruff check rocklab tests benchmarks examples
	$(VENV)/bin/ruff format --check rocklab tests benchmarks examples
	$(VENV)/bin/mypy

# the documentation site (MkDocs Material + mkdocstrings), warnings are errors; the pages'
# examples and equation tables are checked first, so the site cannot show rotten commands
# the papers' figures and tables (docs/gallery.md); the thesis's MUL009 figure when ../shared is there
figures: $(STAMP)
	$(PY) -m rocklab papers --out figures $$(test -d ../shared/data/records && echo --records ../shared/data/records)

docs: $(STAMP)
	$(PY) -m pip install --quiet -e ".[docs]"
	$(PY) -m pytest -q -p no:cacheprovider tests/test_docs_examples.py tests/test_papers_page.py
	NO_MKDOCS_2_WARNING=1 $(VENV)/bin/mkdocs build --strict --site-dir site
	@echo "open site/index.html (works from disk) or 'make docs-serve'"

# the site served with live reload at http://127.0.0.1:8000 (DOCS_ADDR=0.0.0.0:8000 for the lab's network)
DOCS_ADDR ?= 127.0.0.1:8000
docs-serve: $(STAMP)
	$(PY) -m pip install --quiet -e ".[docs]"
	NO_MKDOCS_2_WARNING=1 $(VENV)/bin/mkdocs serve --dev-addr $(DOCS_ADDR)

bench: $(STAMP)
	@for f in benchmarks/bench_*.py; do echo "== $$f"; $(PY) $$f || exit 1; done

clean:
	rm -rf $(VENV) build *.egg-info site
