# Set-up and entry points. `make demo` and `make test` each install what is missing first.
# As root the Debian packages are installed directly, otherwise through sudo.
SHELL := /bin/bash
VENV ?= .venv
PY := $(VENV)/bin/python
NP ?= 2
# the linters `make test` runs, pinned as in pyproject.toml's `lint` extra
LINTERS := ruff==0.17.6 mypy==2.4.1
OUT ?= results
APT_PACKAGES := python3-dolfinx python3-petsc4py python3-slepc4py python3-mpi4py python3-ufl \
    python3-basix python3-ffcx python3-numpy python3-scipy python3-matplotlib python3-pytest \
    python3-pytest-mpi python3-pytest-timeout python3-pytest-xdist python3-venv python3-pip python3-setuptools \
    python3-wheel python3-dev openmpi-bin build-essential pkg-config libopenblas0-serial \
    python3-gmsh python3-sphinx python3-myst-parser python3-sphinxcontrib.bibtex
# the peer library of benchmarks/bench_getfem.py, installed by `make benchmark` only
BENCH_PACKAGES := python3-getfem
SUDO := $(shell [ "$$(id -u)" = 0 ] || echo sudo)
MPIRUN := mpirun -n $(NP) $(shell [ "$$(id -u)" = 0 ] && echo --allow-run-as-root) --oversubscribe
export OMPI_MCA_rmaps_base_oversubscribe := 1
export PYTHONDONTWRITEBYTECODE := 1

.PHONY: setup demo lint docs test test-serial test-mpi test-debian13 benchmark clean

$(VENV)/.installed: pyproject.toml Makefile
	@missing=$$(for p in $(APT_PACKAGES); do dpkg-query -W -f='$${Status}' $$p 2>/dev/null \
	    | grep -q "install ok installed" || echo $$p; done); \
	if [ -n "$$missing" ]; then \
	    echo "installing Debian packages:" $$missing; \
	    $(SUDO) apt-get update && DEBIAN_FRONTEND=noninteractive $(SUDO) apt-get install -y \
	        --no-install-recommends $$missing; fi
	/usr/bin/python3 -m venv --system-site-packages $(VENV)
	$(PY) -m pip install --quiet --no-build-isolation --no-deps -e .
	$(PY) -m pip install --quiet $(LINTERS)
	@touch $@

setup: $(VENV)/.installed

demo: setup
	$(PY) -m fenicsfriction block steady --mu-max 1.55 --steps 31 --out $(OUT)/steady-block
	$(PY) -m fenicsfriction block stability --mu-max 1.55 --steps 62 --out $(OUT)/stability-block
	FENICSFRICTION_DEMO_OUT=$(OUT)/stick-slip-block $(MPIRUN) $(PY) demos/demo_block_stick_slip.py
	FENICSFRICTION_DEMO_OUT=$(OUT)/slider $(MPIRUN) $(PY) demos/demo_slider_table2.py
	FENICSFRICTION_DEMO_OUT=$(OUT)/two_body_contact $(MPIRUN) $(PY) demos/demo_two_body_contact.py
	FENICSFRICTION_DEMO_OUT=$(OUT)/rolling_contact $(MPIRUN) $(PY) demos/demo_rolling_contact.py
	FENICSFRICTION_DEMO_OUT=$(OUT)/multicontact $(MPIRUN) $(PY) demos/demo_multicontact.py
	$(MPIRUN) $(PY) -m fenicsfriction run cases/pin-on-disc.toml --out $(OUT)/pin-on-disc
	$(PY) -m fenicsfriction rolling curve --method fastsim --xi-range 0:3e-3:31 --a 6.304e-3 \
	    --b 12.61e-3 --G 82e9 --nu 0.28 --mu 0.3 --Fn 106.7e3 --out $(OUT)/rolling-fastsim

lint: setup
	$(PY) -m ruff check .
	$(PY) -m mypy

# the serial pass on every core (pytest-xdist), one test file per worker so that a module's
# fixtures are built once; the MPI pass cannot share its ranks' cores and runs as one job
test-serial: setup
	$(PY) -m pytest -q --durations=25 -n $(NP) --dist loadfile tests

test-mpi: setup
	$(MPIRUN) $(PY) -m mpi4py -m pytest -q --durations=25 --with-mpi tests

# the HTML documentation (Sphinx + MyST, Debian's packages, nothing downloaded), warnings as errors
docs: setup
	rm -rf build/docs  # afresh: pickled doctrees of another Sphinx (Debian 12 vs 13) break the build
	$(PY) -m sphinx -W --keep-going -q -b html -d build/docs/doctrees docs build/docs/html

test: lint docs test-serial test-mpi

# the same `make test` on Debian 13's FEniCSx (dolfinx 0.9), in a debootstrap chroot (.debian13/)
test-debian13:
	tools/debian13/run-tests.sh

benchmark: setup
	@dpkg-query -W -f='$${Status}' $(BENCH_PACKAGES) 2>/dev/null | grep -q "install ok installed" \
	    || ($(SUDO) apt-get update && DEBIAN_FRONTEND=noninteractive $(SUDO) apt-get install -y \
	        --no-install-recommends $(BENCH_PACKAGES))
	$(PY) benchmarks/bench_steady.py --out $(OUT)/benchmarks
	$(PY) benchmarks/bench_stability.py --out $(OUT)/benchmarks
	$(PY) benchmarks/bench_cea.py --out $(OUT)/benchmarks
	$(PY) benchmarks/bench_dynamics.py --out $(OUT)/benchmarks
	$(PY) benchmarks/bench_oscillators.py --out $(OUT)/benchmarks
	$(PY) benchmarks/bench_scaling.py --out $(OUT)/benchmarks
	$(MPIRUN) $(PY) benchmarks/bench_scaling.py --out $(OUT)/benchmarks
	$(PY) benchmarks/bench_getfem.py --out $(OUT)/benchmarks
	$(PY) benchmarks/bench_contact.py --out $(OUT)/benchmarks
	$(PY) benchmarks/bench_rolling.py --out $(OUT)/benchmarks
	$(PY) benchmarks/bench_rolling_fe.py --out $(OUT)/benchmarks
	$(PY) benchmarks/bench_rolling_methods.py --out $(OUT)/benchmarks
	$(PY) benchmarks/bench_panagiotopoulos.py --out $(OUT)/benchmarks
	$(PY) benchmarks/bench_multicontact.py --out $(OUT)/benchmarks
	$(PY) benchmarks/bench_interaction.py --out $(OUT)/benchmarks
	$(PY) benchmarks/bench_slider.py --out $(OUT)/benchmarks

clean:
	rm -rf .venv .venv-debian13 results build docs/_generated *.egg-info
	@echo "(the Debian 13 chroot .debian13/ is kept: rm -rf .debian13 removes it)"
