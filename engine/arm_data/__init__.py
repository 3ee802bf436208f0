"""The catalogue arms' URDF files (kinematics only: no meshes), read by :mod:`jik.engine.arms`."""
