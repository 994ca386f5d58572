"""Long-wave continuum solvers for Hertzian chains, built on py-pde."""
