"""parksteer: car steering torque at parking speed, after Sharp & Granger."""

__version__ = "0.1.0"
