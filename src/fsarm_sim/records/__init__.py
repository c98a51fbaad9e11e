"""One record schema, measured data, written runs, the results store."""
