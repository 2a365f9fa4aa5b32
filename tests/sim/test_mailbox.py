"""The hand-off between the cell's processes (cell.sim.mailbox) against simpy.Store's order."""

from __future__ import annotations

import pytest
import simpy
from hypothesis import given, settings
from hypothesis import strategies as st

from cell.sim.mailbox import Mailbox, Timer


def _deliveries(box_factory, puts: list[tuple[float, int]], pause: float) -> list[tuple[float, int]]:
    """(instant, item) of each item a consumer takes, items put at the given instants; the
    consumer works ``pause`` s after each item."""
    env = simpy.Environment()
    box = box_factory(env)
    got: list[tuple[float, int]] = []

    def producer():  # noqa: ANN202
        for at, item in puts:
            yield env.timeout(at - env.now)
            box.put(item)

    def consumer():  # noqa: ANN202
        while True:
            item = yield box.get()
            got.append((env.now, item))
            if pause:
                yield env.timeout(pause)

    env.process(producer())
    env.process(consumer())
    env.run(until=puts[-1][0] + pause * (len(puts) + 1) + 1)
    return got


@settings(max_examples=60, deadline=None)
@given(st.lists(st.integers(0, 5), min_size=1, max_size=30), st.sampled_from([0.0, 0.5, 2.0]))
def test_items_arrive_in_order_when_simpy_store_would_deliver_them(gaps, pause):
    """Same items, same instants as simpy.Store (the reference); only the events differ."""
    at, puts = 0.0, []
    for i, gap in enumerate(gaps):
        at += gap
        puts.append((at, i))
    assert _deliveries(Mailbox, puts, pause) == _deliveries(simpy.Store, puts, pause)


def test_a_queued_item_is_taken_without_an_event():
    env = simpy.Environment()
    box = Mailbox(env)
    for item in "abc":
        box.put(item)
    log = []

    def other():  # noqa: ANN202  (scheduled before the consumer's takes)
        yield env.timeout(0)
        log.append("other")

    def consumer():  # noqa: ANN202
        for _ in range(3):
            log.append((yield box.get()))

    env.process(other())
    env.process(consumer())
    env.step()  # other's start
    env.step()  # consumer's start: takes all three at once, before other's timeout
    assert log == ["a", "b", "c"]
    env.run()
    assert log == ["a", "b", "c", "other"] and len(box) == 0


def test_put_after_wakes_the_receiver_then_the_sender_at_the_instant():
    env = simpy.Environment()
    box = Mailbox(env)
    log = []

    def receiver():  # noqa: ANN202
        while True:
            item = yield box.get()
            log.append(("received", item, env.now))

    def sender():  # noqa: ANN202
        yield env.timeout(1.0)
        event = box.put_after("part", 2.5)
        got = yield event
        log.append(("sender resumed", got, env.now))

    env.process(receiver())
    env.process(sender())
    env.run()
    assert log == [("received", "part", 3.5), ("sender resumed", "part", 3.5)]


def test_put_after_needs_a_waiting_receiver_and_an_empty_box():
    env = simpy.Environment()
    box = Mailbox(env)
    with pytest.raises(RuntimeError):
        box.put_after("x", 1.0)            # nobody waits
    box.put("queued")
    with pytest.raises(RuntimeError):
        box.put_after("x", 1.0)            # an item is queued


def test_one_waiting_process_at_a_time():
    env = simpy.Environment()
    box = Mailbox(env)
    box.get()
    with pytest.raises(RuntimeError):
        box.get()


def test_a_box_reuses_its_events_and_still_delivers_every_item_once():
    env = simpy.Environment()
    box = Mailbox(env)
    got = []

    def consumer():  # noqa: ANN202
        while True:
            got.append(((yield box.get()), env.now))

    def producer():  # noqa: ANN202
        for i in range(5):
            yield env.timeout(1.0)
            box.put(i)
            if i % 2:
                box.put(-i)                # a second one queued behind it

    env.process(consumer())
    env.process(producer())
    env.run()
    assert got == [(0, 1.0), (1, 2.0), (-1, 2.0), (2, 3.0), (3, 4.0), (-3, 4.0), (4, 5.0)]


@settings(max_examples=40, deadline=None)
@given(st.lists(st.sampled_from([0.0, 0.5, 1.0, 2.5]), min_size=1, max_size=12))
def test_a_timer_wakes_its_process_as_a_timeout_would(delays):
    """Two processes waiting on the same delays, one on a Timer and one on env.timeout,
    wake in the same order as two on env.timeout."""
    def wakes(use_timer: bool) -> list[tuple[float, str]]:
        env = simpy.Environment()
        log: list[tuple[float, str]] = []

        def waiter(name: str, wait):  # noqa: ANN001, ANN202
            for d in delays:
                yield wait(d)
                log.append((env.now, name))

        env.process(waiter("a", Timer(env).after if use_timer else env.timeout))
        env.process(waiter("b", env.timeout))
        env.run()
        return log

    assert wakes(True) == wakes(False)


def test_a_waiting_event_is_not_triggered_until_an_item_is_put():
    """As on SimPy's own events: pending while the receiver waits, triggered once put, the
    box's re-armed event too (it used to say triggered while it waited)."""
    env = simpy.Environment()
    box = Mailbox(env)
    states = []

    def consumer():  # noqa: ANN202
        for _ in range(3):
            event = box.get()
            states.append(event.triggered)
            yield event

    def producer():  # noqa: ANN202
        for i in range(3):
            yield env.timeout(1.0)
            getter = box._getter
            box.put(i)
            states.append(getter.triggered)

    env.process(consumer())
    env.process(producer())
    env.run()
    assert states == [False, True, False, True, False, True]


def test_another_simpy_version_is_refused_with_what_to_install():
    from cell.sim.mailbox import check_simpy

    check_simpy("4.1.1")
    for version in ("4.2.0", "5.0", "3.0.13", "dev"):
        with pytest.raises(ImportError,
                           match=r"SimPy 4\.1 \(found SimPy .*pip install 'simpy>=4\.1\.1,<4\.2'"):
            check_simpy(version)


@pytest.mark.parametrize("policy", ["adaptive", "non-adaptive"])
def test_the_model_gives_the_same_parts_with_simpy_store_and_env_timeout(monkeypatch, baseline, policy):
    """The whole cell run with the public-API hand-offs (simpy.Store, env.timeout) in place
    of Mailbox and Timer: every part's record and every belt change the same, bit for bit."""
    from cell.sim import conveyors, feeder, robot
    from cell.sim.mailbox import StoreMailbox, TimeoutTimer
    from cell.sim.simulation import simulate

    scenario = baseline.with_overrides({"run.parts": 300, "controller.policy": policy})
    fast = simulate(scenario)
    for module, name, public in ((conveyors, "Mailbox", StoreMailbox), (robot, "Mailbox", StoreMailbox),
                                 (feeder, "Timer", TimeoutTimer)):
        monkeypatch.setattr(module, name, public)
    reference = simulate(scenario)
    # repr: every float to the last bit, NaN equal to NaN
    assert repr(fast.records) == repr(reference.records) and len(fast.records) == 300
    assert repr(fast.belt_changes) == repr(reference.belt_changes)
    assert repr(fast.summary) == repr(reference.summary)
    assert fast.summary.parts_missed > 0 or policy == "adaptive"   # the runs exercise a lost part
