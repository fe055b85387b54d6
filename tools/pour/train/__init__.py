"""The trainer: REINFORCE on the softmax-linear policy, its config and its rollout executors."""
