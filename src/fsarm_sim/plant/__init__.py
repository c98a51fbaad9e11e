"""Physical laws: effects, transmissions and the shaft catalogue (pure, compilable)."""
