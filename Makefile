# Every target sets up what it needs when missing (idempotent): a local .venv with the
# package and its test extra, a Vulkan driver for GGUI (Debian's mesa-vulkan-drivers) and a
# Japanese font for --lang ja (Debian's fonts-ipafont-gothic).
PYTHON ?= python3
VENV := .venv
PY := $(VENV)/bin/python
STAMP := $(VENV)/.crowndemo-installed

.PHONY: setup vulkan fonts demo test test-slow validate bench device-wheels clean

setup: $(STAMP) vulkan fonts

# Taichi 1.7.4 has wheels for Python 3.9-3.12, pysplashsurf for 3.10 on (pyproject's
# requires-python: 3.10-3.12); a .venv left without a working pip (an interrupted or failed
# set-up) is made again; Debian splits venv into python3-venv, installed here when missing
# (as root).
$(STAMP): pyproject.toml
	@$(PYTHON) -c 'import sys; v = sys.version_info[:2]; sys.exit(0 if (3, 10) <= v < (3, 13) else "error: crowndemo needs Python 3.10 to 3.12 (Taichi 1.7.4 and pysplashsurf have no wheels together for %d.%d); run make with PYTHON=python3.12, say" % v)'
	@$(PY) -m pip --version >/dev/null 2>&1 || { \
	  rm -rf $(VENV); \
	  $(PYTHON) -m venv $(VENV) 2>/dev/null || { \
	    if [ "$$(id -u)" = 0 ] && command -v apt-get >/dev/null 2>&1; then \
	      echo "installing python3-venv (Debian's venv module)"; \
	      rm -rf $(VENV); \
	      (apt-get install -y -qq python3-venv >/dev/null 2>&1 || \
	       (apt-get update -qq && apt-get install -y -qq python3-venv >/dev/null)) && \
	      $(PYTHON) -m venv $(VENV); \
	    else \
	      echo "error: $(PYTHON) -m venv failed: install python3-venv (Debian) and run make again"; \
	      exit 1; \
	    fi; }; }
	$(PY) -m pip install --quiet --upgrade pip
	$(PY) -m pip install --quiet -e '.[test]'
	touch $(STAMP)

# GGUI needs a Vulkan driver; on a machine without a GPU, Mesa's lavapipe provides one.
vulkan:
	@if ls /usr/share/vulkan/icd.d/*.json >/dev/null 2>&1 || ls /etc/vulkan/icd.d/*.json >/dev/null 2>&1; then \
	  true; \
	elif [ "$$(id -u)" = 0 ] && command -v apt-get >/dev/null 2>&1; then \
	  echo "installing mesa-vulkan-drivers (software Vulkan for offscreen rendering)"; \
	  (apt-get install -y -qq mesa-vulkan-drivers >/dev/null 2>&1 || \
	   (apt-get update -qq && apt-get install -y -qq mesa-vulkan-drivers >/dev/null)); \
	else \
	  echo "warning: no Vulkan driver found; install mesa-vulkan-drivers (Debian) for offscreen rendering"; \
	fi

# Japanese captions and title cards (--lang ja) need a CJK font: where the package's own lookup
# (crowndemo/render/captions.py) finds none, IPA Gothic (3.5 MB download, 12.5 MB installed).
fonts: $(STAMP)
	@if $(PY) -c 'import sys; from crowndemo.render.captions import cjk_font_path; sys.exit(cjk_font_path() is None)' >/dev/null 2>&1; then \
	  true; \
	elif [ "$$(id -u)" = 0 ] && command -v apt-get >/dev/null 2>&1; then \
	  echo "installing fonts-ipafont-gothic (a Japanese font for --lang ja)"; \
	  (apt-get install -y -qq --no-install-recommends fonts-ipafont-gothic >/dev/null 2>&1 || \
	   (apt-get update -qq && apt-get install -y -qq --no-install-recommends fonts-ipafont-gothic >/dev/null)); \
	else \
	  echo "warning: no Japanese font found; install fonts-ipafont-gothic or fonts-noto-cjk (Debian) for --lang ja"; \
	fi

# The 2m-drop draft as one quarter (symmetry planes x = 0, y = 0) on the analytic plane floor:
# a quarter of the particles, the same crown (README, "Symmetry planes"), about a minute here.
demo: setup
	$(VENV)/bin/crowndemo record 2m-drop --fast-compile --set quality.draft.symmetry=quarter \
	  --set numerics.wall_model=plane

# One pytest-xdist worker per core (at most 4), each test file on one worker: most of the
# suite's time is compiling kernels, one core per process, and a file's tests share them.
# CROWNDEMO_FAST_COMPILE=1: Taichi's advanced IR optimisations off on the CPU, the same
# equations compiled ~3x faster (BENCHMARKS.md, "Compiling"); tests that need the default
# compile set it themselves (test_backend.py), and `make test-slow` compiles as users do.
test: setup
	CROWNDEMO_FAST_COMPILE=1 $(PY) -m pytest -q -n auto --maxprocesses 4 --dist loadfile -m "not slow"

# The tests of minutes (pytest -m slow): the quarter crown against the whole run's quadrants,
# the 3D cases of the predictor list (the 2D ones, in make test, take the same paths).
test-slow: setup
	$(PY) -m pytest -q -m slow

# The full validation suite (issue 5): every case at three resolutions and its settings
# variants, the stability suite and the seed's crown verdicts; rewrites VALIDATION.md.
validate: setup
	$(PY) -m pip install --quiet -e '.[test,plot]'
	$(VENV)/bin/crowndemo validate --record

bench: setup
	$(VENV)/bin/crowndemo bench

# Taichi and dill as wheels for a lent GPU machine, which has Python 3.12 and the rest of what
# crowndemo needs but not these: tools/device-measure.sh installs them from .whl/ there.
device-wheels:
	mkdir -p .whl
	$(PYTHON) -m pip download --quiet --no-deps --only-binary=:all: --python-version 3.12 \
	  --implementation cp --platform manylinux_2_27_x86_64 --platform manylinux2014_x86_64 \
	  -d .whl taichi==1.7.4 dill

clean:
	rm -rf $(VENV) .pytest_cache
