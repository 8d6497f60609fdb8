"""Benchmarks that regenerate and evaluate the paper's results (one subpackage per benchmark)."""
