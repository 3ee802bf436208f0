"""The HTTP side: the app factory, thin routes, one error mapping and the ``jik serve`` runner.

It imports :mod:`jik.app.compute` and the dashboard modules; nothing outside it imports it.
"""
