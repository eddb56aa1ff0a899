"""Synthetic data: the hand, the logger, closed-form stand-ins and the data sets made from the model."""
