"""Tools for the LCM link: channel names, generated message types, and the pour-lcm-* programs."""
