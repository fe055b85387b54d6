"""The simulator: the libpoursim binding, the episode sources the trainer uses and the Gymnasium environment."""
