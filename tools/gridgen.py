"""gridgen.py — what the scene generators of grid media share (gen_glow.py,
gen_fireball.py): sampling a field at the centres of a grid's cells, in the order the
scene format reads a grid's values (x fastest, then y, then z; docs/scene-format.md),
and writing the values as the rows of a scene file's block."""


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
