"""``CellEnv``: the simulated cell as a Gymnasium environment (docs/rl.md).

One step is one decision of the controller (a part at B with the robot free).  The environment
runs the very run ``cell run`` runs (:class:`cell.sim.simulation.Run`), with :class:`Agent` as
its policy: when the controller asks it for a plan (the controller's one call to any policy,
:meth:`~cell.sim.policies.base.Policy.plan`) the run stops right there, inside that call, until
the agent's action comes back through :meth:`CellEnv.step`.  So nothing in the cell moves
between a decision and its answer, in any order other than ``cell run``'s: the run is the run
the same decisions make there, to the bit.

Why not a yield: the controller could wait on an event at the decision, but the input
conveyor's process wakes on the same event right after it and times the next part on the belt
as the controller has just replanned it (:mod:`cell.sim.conveyors`); a pause there would time it
on the old belt.  So the run keeps its place in a thread of its own, which only ever runs while
the caller waits for it (a hand-off in turn through a pair of locks, as a coroutine would).

An episode with seed s sees the parts ``cell run`` sees with ``run.seed: s``.
"""

from __future__ import annotations

import threading
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import gymnasium as gym
import numpy as np
from gymnasium import spaces

from cell.plumbing.errors import ScenarioError
from cell.rl import observe
from cell.rl.actions import ActionMap, action_of
from cell.scenario.schema import Scenario, load_scenario
from cell.sim.assembly import AssembledCell, assemble
from cell.sim.policies.base import CellConstants, CellView, Plan, Policy
from cell.sim.records import RODE_OFF, SCRAPPED, SPACING_OFF
from cell.sim.run_cost import options_per_h
from cell.sim.simulation import Run, SimResult

#: The environment's name with gymnasium.
ENV_ID = "cell/TransferCell-v0"
#: The reward's terms and their default weights: +1 a part set down.
REWARD = {"delivered": 1.0, "lost": 0.0, "spacing_off": 0.0, "cost": 0.0}


class Abandoned(BaseException):
    """The episode was left before its end (a reset, a close): its run stops where it waits.
    A BaseException, so that the controller does not take it for a policy's failure."""


class Agent(Policy):
    """The policy whose decisions come from outside the run: :meth:`plan` hands the decision's
    view to the environment and waits for the plan it sends back."""

    name = "agent"

    def __init__(self, k: CellConstants, controller: Any = None, file: object = None):
        super().__init__(k, controller, file)
        self.asked: tuple[str, Any] = ("", None)
        """To the environment: ``("decide", view)``, or the run's end (``("end", result)``,
        ``("error", exception)``)."""
        self.answer: Any = None
        """From the environment: the plan, or :class:`Abandoned`."""
        self.to_env, self.to_run = threading.Lock(), threading.Lock()
        self.to_env.acquire()
        self.to_run.acquire()

    def plan(self, view: CellView) -> Plan:
        answer = self.tell("decide", view)
        if answer is Abandoned:
            raise Abandoned
        return answer

    def tell(self, what: str, value: Any) -> Any:
        """(The run's side) hand ``(what, value)`` to the environment and wait for its answer."""
        self.asked = (what, value)
        self.to_env.release()
        if what != "decide":
            return None
        self.to_run.acquire()
        return self.answer

    def reply(self, answer: Any) -> None:
        """(The environment's side) answer the decision the run waits at."""
        self.answer = answer
        self.to_run.release()

    def hear(self) -> tuple[str, Any]:
        """(The environment's side) wait for the run's next word."""
        self.to_env.acquire()
        return self.asked


def play(run: Run, agent: Agent) -> None:
    """The run, to its end (the thread's one job): its result or its error told to the
    environment, nothing if it was abandoned."""
    try:
        run.go()
        result = run.result()
    except Abandoned:
        return
    except BaseException as exc:  # noqa: BLE001 - handed to the caller, raised there
        agent.tell("error", exc)
        return
    agent.tell("end", result)


class CellEnv(gym.Env):
    """The cell of ``scenario`` (a :class:`Scenario`, a file or a built-in scenario's name)
    as an environment; ``reward``: weights of the reward's terms (:data:`REWARD`); ``keep_parts``:
    keep the episode's rows (:attr:`result` then has them, as ``cell run``'s parts.csv)."""

    metadata = {"render_modes": []}

    def __init__(self, scenario: Scenario | str | Path = "baseline",
                 reward: Mapping[str, float] | None = None, keep_parts: bool = False):
        s = scenario if isinstance(scenario, Scenario) else load_scenario(scenario)
        weights = dict(REWARD)
        for key, value in (reward or {}).items():
            if key not in REWARD:
                raise ScenarioError("reward", f"reward.{key}", value,
                                    f"not a reward term; the terms are {', '.join(REWARD)}")
            weights[key] = float(value)
        if weights["cost"] and s.costs is None:
            raise ScenarioError(s.source, "reward.cost", weights["cost"],
                                "the scenario has no costs: section")
        self.scenario, self.weights, self.keep_parts = s, weights, keep_parts
        built = assemble(s)
        self.k = built.k
        self.actions = ActionMap(self.k)
        lo, hi = self.actions.low_high()
        self.action_space = spaces.Box(lo, hi, dtype=np.float64)
        lo, hi = observe.low_high()
        self.observation_space = spaces.Box(lo, hi, dtype=np.float64)
        self.cell = AssembledCell(s, built.timing, self.k, Agent(self.k))
        self.agent: Agent = self.cell.policy  # type: ignore[assignment]
        self.run: Run | None = None
        self.thread: threading.Thread | None = None
        self.view: CellView | None = None
        """The controller's view at the decision waiting for the agent (for an agent that
        decides as a policy would, e.g. the thesis's adaptive rule; None: none waits)."""
        self.result: SimResult | None = None
        """The finished episode's result (summary, and rows with ``keep_parts``)."""
        self.counted = 0
        self.seeded = False
        self.last_s = 0.0
        self.part_value = s.costs.part_value if s.costs is not None else 0.0
        self.hourly = options_per_h(s) if s.costs is not None else 0.0
        """The cost reward's prices: a part lost, an hour of the options the scenario has."""

    # ------------------------------------------------------------------ gymnasium's API
    def reset(self, *, seed: int | None = None,
              options: dict[str, Any] | None = None) -> tuple[np.ndarray, dict[str, Any]]:
        super().reset(seed=seed)
        if seed is not None:
            episode = int(seed)
        elif not self.seeded:
            episode = int(self.scenario.run.seed)
        else:
            episode = int(self.np_random.integers(2**31))
        self.seeded = True
        self.abandon()
        self.run = Run(self.cell, episode, keep_parts=self.keep_parts, keep_belts=False)
        self.result, self.counted, self.last_s = None, 0, 0.0
        self.thread = threading.Thread(target=play, args=(self.run, self.agent), daemon=True,
                                       name=f"cell episode {episode}")
        self.thread.start()
        done = self.advance()
        # nothing is done before the first decision; its time is counted at the first step
        return (observe.empty() if done else self.observation()), {"seed": episode}

    def step(self, action: Any) -> tuple[np.ndarray, float, bool, bool, dict[str, Any]]:
        view = self.view
        if view is None:
            raise RuntimeError("step() before reset(), or after the episode ended")
        self.agent.reply(self.actions.to_plan(action, view.input_speed()))
        done = self.advance()
        reward = self.reward_since()
        info: dict[str, Any] = {}
        if done:
            assert self.result is not None
            info["summary"] = self.result.summary
        return (observe.empty() if done else self.observation()), reward, done, False, info

    # ------------------------------------------------------------------ the run
    def advance(self) -> bool:
        """Let the run go on to its next decision (False) or to its end (True: :attr:`result`
        made); a run's error is raised here."""
        what, value = self.agent.hear()
        self.view = value if what == "decide" else None
        if what == "error":
            self.thread = None
            raise value
        if what == "end":
            self.result, self.thread = value, None
            return True
        return False

    def abandon(self) -> None:
        """Leave the episode under way, if any (its thread ends where it waits)."""
        if self.thread is not None:
            self.agent.reply(Abandoned)
            self.thread.join()
            self.thread = None
        self.view = None

    def close(self) -> None:
        self.abandon()
        super().close()

    def observation(self) -> np.ndarray:
        assert self.run is not None and self.view is not None
        return observe.observe(self.view, self.run.station.robot.free_at_s)

    def reward_since(self) -> float:
        """The reward of the parts done since the last call, and of the time since it."""
        run = self.run
        assert run is not None
        log, w = run.log, self.weights
        start = self.counted
        self.counted = log.handed_on
        now = run.env.now
        hours, self.last_s = (now - self.last_s) / 3600.0, now
        if self.counted == start and not w["cost"]:
            return 0.0
        limits = log.column("limits", start)
        delivered = int(np.count_nonzero(np.isfinite(log.column("touchdown", start))))
        lost = int(np.count_nonzero(limits & RODE_OFF))
        off = int(np.count_nonzero(limits & SPACING_OFF))
        scrapped = int(np.count_nonzero(limits & SCRAPPED))  # in a failure: a cost, not "lost"
        cost = (lost + scrapped) * self.part_value + hours * self.hourly
        return float(w["delivered"] * delivered - w["lost"] * lost - w["spacing_off"] * off
                     - w["cost"] * cost)

    @staticmethod
    def action_of(plan: Plan) -> np.ndarray:
        """The action that is ``plan``."""
        return action_of(plan)


if ENV_ID not in gym.registry:
    gym.register(id=ENV_ID, entry_point="cell.rl.env:CellEnv")
