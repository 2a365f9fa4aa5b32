"""A station (cell.sim.station): the robot, its controller and its two belts' windows, built from
the cell, is a unit a layout can have several of.  Two stations built from the same cell in one
SimPy environment, each fed the same parts, run as two cells: each gives every part the run of
one station alone gives it, to the bit."""

from __future__ import annotations

import simpy

from cell.scenario.schema import load_scenario
from cell.sim.assembly import assemble
from cell.sim.feeder import Feeder
from cell.sim.horizon import run_arrivals
from cell.sim.sim_result import BeltLog
from cell.sim.simulation import RunLog, simulate
from cell.sim.station import Station


def _rows(cell, env, t_list, n, seed) -> list:  # noqa: ANN001
    k, tm = cell.k, cell.k.timing
    rows: list = []
    log = RunLog(t_list, cell.policy.accounting(), None, k.spacing, k.tol, rows,
                 (tm.r1_length_in, tm.r2.length_in, tm.r3_length_in, tm.r4.length_in))
    station = Station(env, cell, seed, log.delivered_part, BeltLog(False, None).told, None)
    feeder = Feeder(env, t_list, station.input, n, k.part_size, log.flag)
    station.control(feeder.fed_s, n, log)
    return rows


def test_two_stations_in_one_environment_run_as_two_cells():
    for name in ("baseline", "non_adaptive"):
        cell = assemble(load_scenario(name, {"run.parts": 150}))
        seed = cell.scenario.run.seed
        alone = simulate(cell).records
        t, n, _ = run_arrivals(cell.scenario, seed)
        env = simpy.Environment()
        first, second = (_rows(cell, env, t.tolist(), n, seed) for _ in range(2))
        env.run()
        assert len(first) == len(second) == len(alone) == 150
        assert repr(first) == repr(second) == repr([tuple(r) for r in alone])


def test_what_can_fail_is_handed_in_and_rewires_nothing():
    """Failures of every piece of equipment, planned stops and a crew: the station's robot,
    belts and controller keep their own methods (none is replaced on the instance), and
    what can stop the robot is the object it was handed."""
    from cell.sim.failures import Downtime

    expon = {"distribution": "expon", "params": {"scale": 300.0}}
    f = {name: {"time_to_failure": expon, "time_to_repair": expon}
         for name in ("robot", "input_belt", "output_belt", "sensor")}
    f["maintenance"] = {"every_h": 0.25, "duration_min": 5.0}
    cell = assemble(load_scenario("baseline", {"run.hours": 1.0, "failures": f}))
    seed, k = cell.scenario.run.seed, cell.k
    t, n, _ = run_arrivals(cell.scenario, seed)
    env = simpy.Environment()
    downtime = Downtime(env, cell.scenario.failures, seed)
    log = RunLog(t.tolist(), cell.policy.accounting(), None, k.spacing, k.tol)
    station = Station(env, cell, seed, log.delivered_part, BeltLog(False, None).told, downtime)
    feeder = Feeder(env, t.tolist(), station.input, n, k.part_size, log.flag)
    station.control(feeder.fed_s, n, log)
    downtime.start()
    env.run(until=3600.0)
    assert len(downtime.all_stops(env.now)) > 3  # the equipment did fail
    for thing in (station.robot, station.input, station.output, station.controller, feeder):
        replaced = [name for name in vars(thing) if callable(getattr(type(thing), name, None))]
        assert replaced == [], (type(thing).__name__, replaced)
    assert station.robot.stops is downtime.robot
