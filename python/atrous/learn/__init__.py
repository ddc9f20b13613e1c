"""The learned à-trous filter's training side (docs/learned.md): features, the differentiable
network + cascade (JAX), the weight file, the training loop. Imported only for training: it needs
jax/optax (.venv-train, scripts/train/setup.sh) and is not imported by the atrous package."""
