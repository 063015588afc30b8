# Two commands do all the set-up on a fresh machine: `make demo` and `make test`.
PY ?= python3
VENV := .venv
BIN := $(VENV)/bin
STAMP_RUN := $(VENV)/.installed-run
STAMP_DEV := $(VENV)/.installed-dev
TORCH := torch==2.13.0
# setuptools reports every editable install as a warning ("Editable installation ... folders with the same name
# as your package"): a notice, not a problem, so it is filtered out; any other warning still shows.
PIP := PYTHONWARNINGS="ignore:Editable installation" $(BIN)/pip --disable-pip-version-check

.PHONY: demo test lint system-deps clean

$(BIN)/python:
	$(PY) -m venv $(VENV)
	$(PIP) install --quiet --upgrade pip setuptools wheel

$(STAMP_RUN): pyproject.toml setup.py | $(BIN)/python
	$(PIP) install --quiet -e .
	touch $@

$(STAMP_DEV): pyproject.toml setup.py | $(BIN)/python
	$(PIP) install --quiet "setuptools>=77" wheel  # tests/test_packaging.py builds the wheel offline with these
	$(PIP) install --quiet $(TORCH)
	$(PIP) install --quiet -e ".[train,dev,scale,pipecat]"
	touch $@ $(STAMP_RUN)

# Debian packages the tests need: PortAudio for sounddevice, Chromium for the viewer test, PulseAudio and
# ALSA's pulse plugin for the virtual microphone (tests/conftest.py, tools/bench/virtual_mic.py); espeak-ng and flite
# speak the TTS voices of the benchmarks.
SYSTEM_PACKAGES := libportaudio2 chromium chromium-driver pulseaudio pulseaudio-utils libasound2-plugins espeak-ng flite
system-deps:
	@if ! ldconfig -p | grep -q libportaudio.so.2 || ! command -v chromedriver >/dev/null \
		|| ! command -v pulseaudio >/dev/null || ! command -v pactl >/dev/null || ! command -v espeak-ng >/dev/null \
		|| ! command -v flite >/dev/null \
		|| ! ls /usr/lib/*/alsa-lib/libasound_module_pcm_pulse.so >/dev/null 2>&1; then \
		if [ "$$(id -u)" = 0 ]; then \
			apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq \
				$(SYSTEM_PACKAGES) >/dev/null; \
		else \
			echo "install $(SYSTEM_PACKAGES) (Debian packages) first"; \
		fi; \
	fi

demo: $(STAMP_RUN)
	$(BIN)/gesturecast demo

# the suite in two processes, each test file in one (its module fixtures built once; ports and daemons are per test)
test: system-deps $(STAMP_DEV)
	$(BIN)/ruff check .
	$(BIN)/python -m pytest -n 2 --dist loadfile

lint: $(STAMP_DEV)
	$(BIN)/ruff check .

clean:
	rm -rf $(VENV) .cache out
