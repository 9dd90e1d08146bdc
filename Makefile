.PHONY: run test setup bench lint figures
run:
	bash scripts/run.sh
test:
	bash scripts/test.sh
setup:
	bash scripts/setup.sh
bench:
	bash scripts/setup.sh && .venv/bin/python -m pip install -q -e ".[bench]" && .venv/bin/python benchmarks/run.py
lint:
	.venv/bin/ruff format --check meshcore app tests benchmarks tools scripts
	.venv/bin/ruff check meshcore app tests
