"""Electric power assistance acting at the pinion: the electric assist of electric_assist.py at this point of action."""

from __future__ import annotations

from .electric_assist import ElectricAssist

EFFECT = ElectricAssist.at("pinion")()
