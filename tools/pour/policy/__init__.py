"""The policy as the firmware runs it: float and fixed-point reference, weights.h, the firmware core through ctypes."""
