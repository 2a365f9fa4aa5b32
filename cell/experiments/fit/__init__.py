"""Input modelling for ``cell fit``: distributions fitted to a trace by maximum likelihood
(:mod:`cell.experiments.fit.mle`), the data read, the pattern tests, the choice and the block
written."""
