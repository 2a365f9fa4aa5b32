"""Table 7.1 beside the thesis: the table (:mod:`cell.reporting.table_7_1.table`) and its reading
(:mod:`cell.reporting.table_7_1.sentences`)."""
