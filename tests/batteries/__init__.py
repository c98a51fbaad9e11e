"""The diagnosis's test batteries, kept out of the installed package: ``battery`` (one hidden
effect at a time), ``battery_expert`` and ``battery_arm_expert`` (co-occurring effects, issue 16),
run by tests and by ``scripts/discrepancy_battery*.py``; and ``gen_bench``, the outside generator
written apart from the diagnosis (issue 28): it imports nothing of it."""
