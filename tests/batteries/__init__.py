"""Battery generators written apart from the diagnosis (issue 28): they import nothing of it."""
