"""Instruction-following benchmark: labelled states from real recipes, the IF metric, policies and baselines."""
