"""A Python client of the wingman planner service over iceoryx2.

`contract` is the message contract, generated from the planner's code (ctypes structs,
constants, enum values, the services' settings); `Client` opens one vehicle's services
with those settings and publishes, notifies and waits for the planner's status echo.
"""

from . import contract
from .client import Client, PlannerTimeout

__all__ = ["Client", "PlannerTimeout", "contract"]
