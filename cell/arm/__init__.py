"""The arm's maths on plain values: frames, kinematics, the path, motors, the
joint-step table, dynamics and the minimum-time planner (thesis §2-4, §6.1; Shin & McKay)."""
