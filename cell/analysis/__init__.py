"""Analysis of experiments: statistics over replications (:mod:`cell.analysis.stats`)
and input modelling, fitting inter-arrival distributions to traces (:mod:`cell.analysis.fit`)."""
