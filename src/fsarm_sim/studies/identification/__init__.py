"""Parameter identification from measured data (least squares on published model structures)."""
