"""MJCF models shipped with fsarm-sim (installed as ``fsarm_sim.models``)."""
