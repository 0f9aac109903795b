# One command each, on a fresh machine: `make demo` installs and runs the plate example,
# `make test` installs and runs the test suite, `make validate` runs the comparisons of
# validation/ with exact answers and peers (FElupe from the `bench` extra; CalculiX's ccx from
# apt-get where it is missing and make runs as root, else those comparisons are skipped).
PYTHON ?= python3
VENV := .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed

.PHONY: install demo test validate clean

$(STAMP): pyproject.toml
	$(PYTHON) -m venv $(VENV)
	$(BIN)/pip install -q --upgrade pip
	$(BIN)/pip install -q -e ".[test]"
	touch $(STAMP)

install: $(STAMP)

demo: $(STAMP)
	$(BIN)/axiform run examples/hughes_carnoy_plate.toml --out results/hughes_carnoy_plate

test: $(STAMP)
	$(BIN)/python -m pytest -n 2

# each script asserts its agreements (exit 1 on a failure) and writes validation/results/
VALIDATE = "heat_ccx.py" "toric_ccx.py" "die_drawing_ccx.py" "plate_peers.py" \
	"toric_plate.py --repeat 1 --no-symmetric" "plate_elements.py --repeat 1 --no-committed --ccx-mesh 4x40" \
	"cold_mould_freezing.py" "pet_networks.py"

validate: $(STAMP)
	$(BIN)/pip install -q -e ".[test,bench]"
	@if ! command -v ccx >/dev/null; then \
		if [ "$$(id -u)" = 0 ]; then apt-get update -q && apt-get install -y -q calculix-ccx; \
		else echo "validate: ccx not found and not root: the CalculiX comparisons will be skipped"; fi; fi
	@failed=""; for script in $(VALIDATE); do \
		echo "== validation/$$script"; \
		$(BIN)/python validation/$$script || failed="$$failed $$script"; \
	done; \
	if [ -n "$$failed" ]; then echo "validate: FAILED:$$failed"; exit 1; fi; echo "validate: every comparison holds"

clean:
	rm -rf $(VENV) results
