"""Analysis of experiments: statistics over replications (:mod:`cell.experiments.stats`)
and input modelling, fitting inter-arrival distributions to traces (:mod:`cell.experiments.fit.mle`)."""
