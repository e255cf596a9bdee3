"""Algorithm 1 of the paper, in separate pieces (in the manner of pymanopt):

* :mod:`.manifold`: the product of spheres and the Cayley retraction (Theorem 1);
* :mod:`.energy`: the interface of an energy, and :mod:`.harmonic` the harmonic
  energy (Eqs. 6, 13) with :func:`.harmonic.harmonic_map`;
* :mod:`.direction`: the search direction in the L2 or H1 metric, with its
  solvers (:mod:`.preconditioner`, :mod:`.amg`);
* :mod:`.step_size`: Barzilai-Borwein steps (Eq. 12);
* :mod:`.line_search`: the Zhang-Hager nonmonotone search;
* :mod:`.barrier`: fixed vertices and the fold barrier;
* :mod:`.gauge`: the Möbius gauge;
* :mod:`.minimize`: the loop, and :mod:`.result` its result object.

Adding an energy: subclass :class:`.energy.Energy` in a new file and pass it to
:func:`.minimize.minimize`.
"""
