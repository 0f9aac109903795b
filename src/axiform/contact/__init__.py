"""Contact of the body with rigid moulds (paper section 3)."""
