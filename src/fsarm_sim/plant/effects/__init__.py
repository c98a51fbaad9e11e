"""Constitutive laws, one physical effect per module.

Each law is a small pure function over floats (no MuJoCo, no Python objects) so that Numba can
compile it for the native callback path. The simulator only wires them together.
"""
