"""fsarm-sim: MuJoCo simulator of a 3-DOF arm whose elbow is driven through a flexible shaft."""

__version__ = "0.5.4"
