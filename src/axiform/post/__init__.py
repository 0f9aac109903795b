"""What is read off the results: fields, thickness, labels, plots."""
