"""gridgen.py — what the scene generators of grid media share (gen_glow.py,
gen_fireball.py, gen_smoke.py, gen_cloud.py): sampling a field at the centres of a
grid's cells, in the order the scene format reads a grid's values (x fastest, then y,
then z; docs/scene-format.md), writing the values as the rows of a scene file's block,
and a deterministic value noise (no random module, so every file is reproduced
exactly)."""
import math


def hash3(x, y, z):
    """A lattice point's pseudo-random value in [0, 1] (integer hashing)."""
    h = (x * 73856093) ^ (y * 19349663) ^ (z * 83492791)
    h = (h ^ (h >> 13)) * 0x5bd1e995 & 0xffffffff
    return ((h ^ (h >> 15)) & 0xffff) / 65535.0


def value_noise(x, y, z):
    """Trilinear value noise on the integer lattice, smoothstepped."""
    xi, yi, zi = math.floor(x), math.floor(y), math.floor(z)
    fx, fy, fz = x - xi, y - yi, z - zi
    sx, sy, sz = (f * f * (3 - 2 * f) for f in (fx, fy, fz))
    v = 0.0
    for dz in (0, 1):
        for dy in (0, 1):
            for dx in (0, 1):
                w = (sx if dx else 1 - sx) * (sy if dy else 1 - sy) * (sz if dz else 1 - sz)
                v += w * hash3(xi + dx, yi + dy, zi + dz)
    return v


def sample(field, nx, ny, nz, y_from_zero=False):
    """The lists of each value field(x, y, z) returns, over the cells' centres: x and z
    in [-1, 1], y in [-1, 1] or, with y_from_zero, in [0, 1]."""
    columns = None
    for k in range(nz):
        for j in range(ny):
            for i in range(nx):
                y = (j + 0.5) / ny if y_from_zero else ((j + 0.5) / ny) * 2 - 1
                values = field(((i + 0.5) / nx) * 2 - 1, y, ((k + 0.5) / nz) * 2 - 1)
                if columns is None:
                    columns = [[] for _ in values]
                for column, v in zip(columns, values):
                    column.append(v)
    return columns


def block(values, nx):
    """The values as rows of nx, indented for a medium's block, 4 significant digits."""
    return "\n".join("        " + " ".join("%.4g" % v for v in values[a:a + nx])
                     for a in range(0, len(values), nx))
