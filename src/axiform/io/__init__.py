"""The results folder: writer, checkpoints, VTU, GiD and revolved files."""
