"""Controllers: pure functions, measurements and references in, commands out.

No simulator imports here: the same functions run in the Python control callback, in Numba-compiled
native callbacks, and on a real robot's control PC.
"""
