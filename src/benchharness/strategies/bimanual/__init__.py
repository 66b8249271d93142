"""The bimanual Rubik's state machine every two-armed robot's Rubik's strategy runs on.

Modules: :mod:`.config` (``BimanualConfig``, the fields every robot has),
:mod:`.frames` (grip geometry from an *estimated* cube pose, no physics),
:mod:`.machine` (``BimanualRubiksMachine``, the trial, and ``GraspModule``,
what a robot contributes). Not a strategy plugin itself: the robots'
packages (``pr2_rubiks``, ``herb_rubiks``) register strategies built from it.
See docs/strategies.md, "The bimanual state machine" and "Adding a robot".
"""
