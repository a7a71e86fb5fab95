"""Walls: every closed boundary of the model, as straight segments, in one package.

A wall is a polyline (a closed one is a solid footprint); the DEM border is four of them when
the edges are closed. Three mechanisms keep water on its side:

1. **Mirror particles.** For a particle i near a wall segment, every neighbour j on i's side
   (i itself included) contributes a mirror image x_j' = 2 f_j - x_j (f_j its foot on the
   segment's line), with the same mass, density, alpha and h and the mirrored velocity
   v_j' = v_j - 2 (v_j . n) n (free slip), if the line from i to the image passes through the
   segment: the images fill the part of i's support hidden from i behind the wall. On a
   straight wall this completes the kernel exactly, so the depth and the pressure of still
   water along a wall are those of the interior (zero-order consistency, the property the
   modified virtual boundary particles of Vacondio, Rogers & Stansby, IJNMF 69 (2012) 226-253
   approximate). Behind a convex corner (a building's) each hidden point is imaged once, by
   the face the line passes through. j's foot need not fall on the segment: where a wall
   bends, a point hidden behind one segment may be the image of a particle in front of the
   next (an earlier version required the foot on the segment, and lost those images near every
   vertex of a polyline). A sight line exactly through a vertex is settled by a fixed shift of
   1 mm (:func:`hides`), so that point is imaged once. In a right-angled corner where two
   near segments meet, j's foot on both gives a third image, the reflection of j's first image
   about the second wall (the point reflection through the corner), which completes the kernel
   there too.
2. **Pair blocking.** Particles on opposite sides of a wall do not interact.
3. **Crossing guard.** A drift step that would cross a wall is reflected about it (position and
   normal velocity), so no particle ever crosses, whatever the time step (:func:`drift`).

Near-wall lists are CSR arrays ``(wstart, wseg)`` built with the neighbour lists, with the
same skin, for the particles within the interaction radius of a segment (and kept as long as
the neighbour lists are: a wall within the support now was within the skinned radius at the
build), together with each particle's corners ``(cstart, cpair)``: the pairs of its near
segments that meet at a right angle, listed in ``wseg`` order. Most particles have none and pay
nothing. Which listed pairs a wall separates is found once per step (:func:`blocked_pairs`)
for the density iterations and the forces.

Modules, one job each:

* ``geometry``: segments from polylines, distances, crossings, reflections;
* ``nodata``: the nodata border of a DEM traced and simplified into polylines;
* ``openings``, ``junctions``: cutting inflow sections out of walls; splitting at T-junctions;
* ``index``: the near-wall lists of the particles;
* ``sight``: pair blocking and the crossing guard;
* ``images``: the mirror images;
* ``seeding``: still-water seeds next to walls, settled and matched to the seeded depth.

The package imports no other floodsph package. Two wall modules
live where their users are: the model's segments (the user's walls, the closed DEM sides and
the nodata border, cut at inflow openings and split at junctions) are assembled in
``floodsph.model.wall_layout``, and the boundary-integral alternative
(``[numerics] wall_model = "integral"``), an integral of the kernel, is ``floodsph.sph.shadow``.
"""
