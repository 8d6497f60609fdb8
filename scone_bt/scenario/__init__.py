"""Headless scenario tests: a situation and the behaviour expected in it, declared in YAML and checked on the
episode's typed event stream (docs/scenarios.md)."""

from scone_bt.scenario.model import Case, ScenarioFile, json_schema, load_scenario, load_scenarios

__all__ = ["Case", "ScenarioFile", "json_schema", "load_scenario", "load_scenarios"]
