"""Command-line entry points: scone-run and scone-models."""
