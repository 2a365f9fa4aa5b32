"""Reports generated from runs and sweeps: any sweep's report -- summary, paired
differences, figures and a reading (:mod:`cell.reporting.experiment.report`) --, Table 7.1
beside the thesis (:mod:`cell.reporting.table_7_1`) and the planner's minimum
cycles (:mod:`cell.reporting.planner_report`)."""
