"""Any sweep's report (``cell sweep --report``, ``cell compare --out``): written by
:mod:`cell.reporting.experiment.report` from its tables, figures and reading."""
