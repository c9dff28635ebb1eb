"""Mapping: pure functions over arrays from posed RGB-D frames to navigation layers.

:mod:`~sgtool.mapping.voxels` (sparse semantic voxel map), :mod:`~sgtool.mapping.bev`
(bird's-eye occupancy), :mod:`~sgtool.mapping.esdf` (distance fields, inflation),
:mod:`~sgtool.mapping.voronoi` (sparsified generalized Voronoi graph),
:mod:`~support.synthetic_world` (a numpy ray-caster of box worlds for tests and benchmarks).
"""
