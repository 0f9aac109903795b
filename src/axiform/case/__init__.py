"""The case file: one module per table (schema and what it builds), the whole case in schema."""
