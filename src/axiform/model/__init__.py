"""The model: its terms, their evaluation and state, and the checks on it."""
