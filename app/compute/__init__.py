"""The computations behind the API: request models to engine calls to response models, run in
worker processes. This package imports the engine, never :mod:`jik.app.api`."""
