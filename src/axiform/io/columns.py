"""The columns of history.csv that every results folder has, before one column per monitor
(time = load_factor: the process time t).  A monitor may not take one of these names
(case.monitor); a sweep reads the monitors as the other columns (app.sweep)."""

HISTORY_COLUMNS = ("step", "load_factor", "time", "iterations")
