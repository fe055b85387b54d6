"""Examples that train the firmware's policy class with other libraries: Stable-Baselines3's PPO (sb3_ppo)."""
