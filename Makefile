# The two commands of the README: `make demo` (main job on the embedded default input)
# and `make test` (the test suite). Both create/refresh .venv/ first.
.PHONY: venv demo test
venv:
	@bash scripts/setup_venv.sh
demo: venv
	@.venv/bin/iemd-demo
test: venv
	@.venv/bin/pytest test
