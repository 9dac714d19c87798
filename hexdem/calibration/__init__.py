"""Calibration from measurements: the model's parameters, with uncertainties, from sensor records
(``hexdem calibrate``). Priors → simulations → emulator → posterior, one module each."""
