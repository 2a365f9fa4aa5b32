"""Reports generated from runs and sweeps: Table 7.1 beside the thesis
(:mod:`cell.reporting.table_7_1`) and the planner's minimum cycles
(:mod:`cell.reporting.mintime`)."""
