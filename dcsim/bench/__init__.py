"""Benchmarks run by ``dcsim bench KIND``: harnesses, and reference solvers that score plugins."""
