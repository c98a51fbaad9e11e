"""The runner and its clock, scenarios, references, outer loops, batches of runs."""
