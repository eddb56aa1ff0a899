"""The numeric half of the model: parameter vectors, drives, simulation; never re-derives."""
