"""The search's kinematic tables are kept per robot object; a robot is built per payload and
mounting (``toptraj.robots.equipment``), so the tables kept are bounded."""

from __future__ import annotations

from toptraj import robots
from toptraj.planners.generators.search import free_space
from toptraj.robots import equipment


def test_tables_of_many_equipped_robots_stay_bounded():
    arm = robots.load("geering_2r")
    for mass in range(1, free_space.MAX_TABLES + 10):
        free_space.chain_tables(equipment.equip(arm, equipment.payload(float(mass))))
    assert len(free_space._TABLES) <= free_space.MAX_TABLES
    latest = equipment.equip(arm, equipment.payload(float(free_space.MAX_TABLES + 9)))
    assert free_space._TABLES[id(latest)][0] is latest
