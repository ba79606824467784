"""Runs: the run configuration, the method registry, one refinement run end to end, sweeps, calibration, notebooks."""
