.PHONY: run test test-fast setup bench lint typecheck figures
run:
	bash scripts/run.sh
test:
	bash scripts/test.sh
test-fast:
	bash scripts/test.sh -m "not slow"
setup:
	bash scripts/setup.sh
bench:
	bash scripts/setup.sh && .venv/bin/python -m pip install -q -e ".[bench]" && .venv/bin/python benchmarks/run.py
typecheck:
	.venv/bin/python scripts/mypy_check.py
lint:
	.venv/bin/ruff format --check meshcore app tests benchmarks tools scripts
	.venv/bin/ruff check meshcore app tests
