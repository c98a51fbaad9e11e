"""What is computed from runs: benches, sweeps, selection, verification, claims."""
