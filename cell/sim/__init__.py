"""The simulated cell: the feeder, conveyors, robot and controller as SimPy processes,
the policies, the records of a run, the thesis's accounting, and simulate()."""
