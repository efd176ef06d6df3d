# rocklab: every target bootstraps .venv from a bare Python 3.11 (idempotent).
PYTHON ?= python3
VENV   := .venv
PY     := $(VENV)/bin/python
STAMP  := $(VENV)/.installed

.PHONY: test test-browser demo bench lint docs venv clean

venv: $(STAMP)

$(STAMP): pyproject.toml
	@test -x $(PY) || $(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --quiet --upgrade pip
	$(PY) -m pip install --quiet -e ".[test]"
	@touch $(STAMP)

# pytest exit code 5 (no tests collected) is a failure too.
test: $(STAMP)
	$(PY) -m pytest -q

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

lint: $(STAMP)
	$(PY) -m pip install --quiet -e ".[lint]"
	$(VENV)/bin/ruff check rocklab tests benchmarks examples
	$(VENV)/bin/ruff format --check rocklab tests benchmarks examples
	$(VENV)/bin/mypy

# the documentation site (MkDocs Material + mkdocstrings), warnings are errors; the pages'
# examples and equation tables are checked first, so the site cannot show rotten commands
docs: $(STAMP)
	$(PY) -m pip install --quiet -e ".[docs]"
	$(PY) -m pytest -q -p no:cacheprovider tests/test_docs_examples.py tests/test_papers_page.py
	NO_MKDOCS_2_WARNING=1 $(VENV)/bin/mkdocs build --strict --site-dir site

bench: $(STAMP)
	@for f in benchmarks/bench_*.py; do echo "== $$f"; $(PY) $$f || exit 1; done

clean:
	rm -rf $(VENV) build *.egg-info site
