"""The hindsight optimum of a run (``cell hindsight``; docs/model.md, "The hindsight optimum"):
:mod:`.optimum` puts together :mod:`.milp` (the proved bound above) and :mod:`.search` (a
schedule run through the simulation below).  Nothing is imported here, so that naming the
package loads no solver."""
