"""The pour CAN protocol from Python: its DBC for any node id and its bus load."""
