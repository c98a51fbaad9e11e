"""Where parameters and states live (layout) and the array kernels the callbacks run."""
