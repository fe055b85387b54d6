"""pour: offline tools for the soymilk-pouring controller."""
