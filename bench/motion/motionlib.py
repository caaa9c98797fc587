"""cellplan motion problems in Python: the problem files (bench/motion/README.md), the robot
(URDF + SRDF), forward kinematics, and an exact collision model of the URDF's collision meshes
against the primitive obstacles with python-fcl.

Used by bench/motion/recheck.py (the independent exact re-check) and bench/peers/motion_ompl.py
(OMPL's state validity checker). Independent of cellplan's Rust code and of VAMP: the URDF is
read here, the meshes are the URDF's collision meshes as triangle soups (fcl.BVHModel, OBBRSS),
obstacles are fcl.Box / fcl.Cylinder / fcl.Sphere.
"""

import json
import math
import struct
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np

FORMAT = "cellplan-motion-problems"


# ---------------------------------------------------------------- problem files


def load_problems(path):
    """Read one problem file; robot paths are resolved against the file's folder."""
    path = Path(path)
    doc = json.loads(path.read_text())
    if doc.get("format") != FORMAT or doc.get("version") != 1:
        raise ValueError(f"{path}: not a {FORMAT} version 1 file")
    robot = doc["robot"]
    if robot.get("tool"):
        # The robot would be checked without its tool: refuse rather than check another robot.
        raise ValueError(f"{path}: robot.tool is not supported here (cellplan bench motion checks it)")
    doc["urdf_path"] = (path.parent / robot["urdf"]).resolve()
    doc["srdf_path"] = (path.parent / robot["srdf"]).resolve() if robot.get("srdf") else None
    base = robot.get("base", {})
    doc["base_tf"] = make_tf(base.get("xyz", [0, 0, 0]), rpy_matrix(*base.get("rpy", [0, 0, 0])))
    for p in doc["problems"]:
        if len(p["start"]) != len(doc["joints"]) or any(len(g) != len(doc["joints"]) for g in p["goals"]):
            raise ValueError(f"{path}: {p['name']}: start/goal length differs from joints")
    return doc


def path_length(path):
    """Sum of joint-space Euclidean segment lengths."""
    q = np.asarray(path, dtype=float)
    if len(q) < 2:
        return 0.0
    return float(np.linalg.norm(np.diff(q, axis=0), axis=1).sum())


# ---------------------------------------------------------------- rotations


def rpy_matrix(r, p, y):
    """URDF rpy: fixed-axis roll about x, then pitch about y, then yaw about z."""
    cr, sr, cp, sp, cy, sy = math.cos(r), math.sin(r), math.cos(p), math.sin(p), math.cos(y), math.sin(y)
    return np.array([
        [cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
        [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
        [-sp, cp * sr, cp * cr],
    ])


def quat_matrix(q):
    x, y, z, w = q
    n = math.sqrt(x * x + y * y + z * z + w * w)
    x, y, z, w = x / n, y / n, z / n, w / n
    return np.array([
        [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
        [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
        [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
    ])


def make_tf(xyz, rot):
    t = np.eye(4)
    t[:3, :3] = rot
    t[:3, 3] = xyz
    return t


_I3 = np.eye(3)


def axis_angle_batch(axis, angles):
    """(N,3,3) rotations about a unit axis (Rodrigues)."""
    a = np.asarray(axis, dtype=float)
    a = a / np.linalg.norm(a)
    k = np.array([[0, -a[2], a[1]], [a[2], 0, -a[0]], [-a[1], a[0], 0]])
    s = np.sin(angles)[:, None, None]
    c = np.cos(angles)[:, None, None]
    return np.eye(3)[None] + s * k[None] + (1 - c) * (k @ k)[None]


# ---------------------------------------------------------------- meshes


def read_stl(path):
    """Vertices (V,3) and faces (F,3) of a binary or ASCII STL, vertices merged exactly."""
    data = Path(path).read_bytes()
    tris = None
    if len(data) >= 84:
        (n,) = struct.unpack_from("<I", data, 80)
        if 84 + 50 * n == len(data):
            rec = np.frombuffer(data, dtype=np.dtype([("n", "<f4", 3), ("v", "<f4", (3, 3)), ("a", "<u2")]),
                                count=n, offset=84)
            tris = rec["v"].astype(np.float64)
    if tris is None:
        text = data.decode("ascii", errors="replace")
        vals = [list(map(float, l.split()[1:4])) for l in text.splitlines() if l.strip().startswith("vertex")]
        tris = np.array(vals, dtype=np.float64).reshape(-1, 3, 3)
    flat = tris.reshape(-1, 3)
    verts, inv = np.unique(flat, axis=0, return_inverse=True)
    faces = inv.reshape(-1, 3).astype(np.int64)
    return verts, faces


def box_vertices(half):
    h = np.asarray(half, dtype=float)
    return np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)]) * h


# ---------------------------------------------------------------- the robot


class Geom:
    """One collision element of a link: kind 'mesh'/'box'/'cylinder'/'sphere', its origin in the
    link frame, and its vertices in the link frame (for bounds)."""

    def __init__(self, kind, origin, **kw):
        self.kind = kind
        self.origin = origin
        self.__dict__.update(kw)


class Robot:
    def __init__(self, urdf_path, srdf_path=None, active_joints=None, base_tf=None):
        self.urdf_path = Path(urdf_path)
        root = ET.parse(self.urdf_path).getroot()
        self.base_tf = np.eye(4) if base_tf is None else np.asarray(base_tf, dtype=float)
        self.links = {}
        for l in root.findall("link"):
            geoms = [self._geom(c) for c in l.findall("collision")]
            self.links[l.get("name")] = [g for g in geoms if g is not None]
        self.joints = []
        for j in root.findall("joint"):
            o = j.find("origin")
            xyz = [float(v) for v in (o.get("xyz", "0 0 0").split() if o is not None else [0, 0, 0])]
            rpy = [float(v) for v in (o.get("rpy", "0 0 0").split() if o is not None else [0, 0, 0])]
            ax = j.find("axis")
            axis = [float(v) for v in ax.get("xyz").split()] if ax is not None else [1.0, 0.0, 0.0]
            lim = j.find("limit")
            self.joints.append({
                "name": j.get("name"),
                "type": j.get("type"),
                "parent": j.find("parent").get("link"),
                "child": j.find("child").get("link"),
                "origin": make_tf(xyz, rpy_matrix(*rpy)),
                "axis": np.asarray(axis) / np.linalg.norm(axis),
                "lower": float(lim.get("lower")) if lim is not None and lim.get("lower") else None,
                "upper": float(lim.get("upper")) if lim is not None and lim.get("upper") else None,
            })
        children = {j["child"] for j in self.joints}
        roots = [l for l in self.links if l not in children]
        if len(roots) != 1:
            raise ValueError(f"{urdf_path}: expected one root link, found {roots}")
        self.root = roots[0]
        # joints in topological order
        by_parent = {}
        for j in self.joints:
            by_parent.setdefault(j["parent"], []).append(j)
        order, stack = [], [self.root]
        while stack:
            link = stack.pop()
            for j in by_parent.get(link, []):
                order.append(j)
                stack.append(j["child"])
        self.joints = order
        for j in order:
            x, y, z = j["axis"]
            j["K"] = np.array([[0, -z, y], [z, 0, -x], [-y, x, 0]])
            j["K2"] = j["K"] @ j["K"]
        self.parent_joint = {j["child"]: j for j in order}
        movable = [j["name"] for j in order if j["type"] in ("revolute", "continuous", "prismatic")]
        self.active = list(active_joints) if active_joints is not None else movable
        missing = set(movable) - set(self.active)
        if missing:
            raise ValueError(f"movable joints not in the problem's joint list: {sorted(missing)}")
        self.index = {n: i for i, n in enumerate(self.active)}
        for j in order:
            if j["type"] == "prismatic":
                raise NotImplementedError("prismatic joints")
        self.collision_links = [l for l in self.links if self.links[l]]
        self.disabled = set()
        if srdf_path is not None:
            sr = ET.parse(srdf_path).getroot()
            for d in sr.findall("disable_collisions"):
                self.disabled.add(tuple(sorted((d.get("link1"), d.get("link2")))))
        adjacent = {tuple(sorted((j["parent"], j["child"]))) for j in order}
        cl = self.collision_links
        self.self_pairs = [
            (a, b)
            for i, a in enumerate(cl)
            for b in cl[i + 1:]
            if tuple(sorted((a, b))) not in self.disabled and tuple(sorted((a, b))) not in adjacent
        ]
        # links joined only by fixed joints move as one body: such pairs never change
        self.body = {}
        for j in order:
            if j["parent"] not in self.body:
                self.body[j["parent"]] = j["parent"]
            self.body[j["child"]] = self.body[j["parent"]] if j["type"] == "fixed" else j["child"]
        self.body.setdefault(self.root, self.root)
        self.rigid_pairs = [p for p in self.self_pairs if self.body[p[0]] == self.body[p[1]]]
        self.moving_pairs = [p for p in self.self_pairs if self.body[p[0]] != self.body[p[1]]]
        self._bounds()

    def _geom(self, c):
        o = c.find("origin")
        xyz = [float(v) for v in (o.get("xyz", "0 0 0").split() if o is not None else [0, 0, 0])]
        rpy = [float(v) for v in (o.get("rpy", "0 0 0").split() if o is not None else [0, 0, 0])]
        origin = make_tf(xyz, rpy_matrix(*rpy))
        g = c.find("geometry")
        m = g.find("mesh")
        if m is not None:
            fn = m.get("filename")
            if fn.startswith("package://"):
                fn = fn[len("package://"):]
            if fn.startswith("file://"):
                fn = fn[len("file://"):]
            path = (self.urdf_path.parent / fn).resolve()
            verts, faces = read_stl(path)
            scale = np.array([float(v) for v in m.get("scale", "1 1 1").split()])
            verts = verts * scale
            # surface samples for the depth measure: vertices, edge midpoints, face centroids
            tri = verts[faces]
            edges = np.unique(np.sort(np.vstack([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]]), axis=1), axis=0)
            surf = np.vstack([verts, verts[edges].mean(axis=1), tri.mean(axis=1)])
            return Geom("mesh", origin, verts=verts, faces=faces, file=str(path),
                        link_verts=verts @ origin[:3, :3].T + origin[:3, 3],
                        surface=surf @ origin[:3, :3].T + origin[:3, 3])
        b = g.find("box")
        if b is not None:
            half = np.array([float(v) for v in b.get("size").split()]) / 2
            bv = box_vertices(half)
            return Geom("box", origin, half=half, link_verts=bv @ origin[:3, :3].T + origin[:3, 3],
                        surface=bv @ origin[:3, :3].T + origin[:3, 3])
        cy = g.find("cylinder")
        if cy is not None:
            r, l = float(cy.get("radius")), float(cy.get("length"))
            ring = np.array([[r * math.cos(t), r * math.sin(t), z] for t in np.linspace(0, 2 * math.pi, 33)
                             for z in (-l / 2, l / 2)]) / math.cos(math.pi / 32)
            return Geom("cylinder", origin, radius=r, length=l, link_verts=ring @ origin[:3, :3].T + origin[:3, 3],
                        surface=ring @ origin[:3, :3].T + origin[:3, 3])
        s = g.find("sphere")
        if s is not None:
            r = float(s.get("radius"))
            return Geom("sphere", origin, radius=r, link_verts=origin[:3, 3][None] + box_vertices([r, r, r]),
                        surface=origin[:3, 3][None])
        return None

    def _bounds(self):
        """Per collision link: a bounding sphere in the link frame. Per active joint: R_j, an
        upper bound on the distance of any collision vertex downstream of the joint from the
        joint's axis, so that a straight joint-space segment dq moves no vertex by more than
        sum_j |dq_j| R_j (the vertex's path length is at most that)."""
        self.sphere = {}
        for l in self.collision_links:
            v = np.vstack([g.link_verts for g in self.links[l]])
            c = (v.min(axis=0) + v.max(axis=0)) / 2
            self.sphere[l] = (c, float(np.linalg.norm(v - c, axis=1).max()))
        # radius of each link's geometry around the link origin
        reach = {l: (float(np.linalg.norm(np.vstack([g.link_verts for g in gs]), axis=1).max()) if gs else 0.0)
                 for l, gs in self.links.items()}
        self.radius_bound = np.zeros(len(self.active))
        for j in self.joints:
            if j["name"] not in self.index:
                continue
            best = 0.0
            # walk the subtree below the joint's child, accumulating the joint-origin offsets
            stack = [(j["child"], 0.0)]
            while stack:
                link, dist = stack.pop()
                best = max(best, dist + reach[link])
                for k in self.joints:
                    if k["parent"] == link:
                        stack.append((k["child"], dist + float(np.linalg.norm(k["origin"][:3, 3]))))
            self.radius_bound[self.index[j["name"]]] = best

    def limits(self):
        lo, hi = [], []
        for n in self.active:
            j = next(j for j in self.joints if j["name"] == n)
            lo.append(j["lower"] if j["lower"] is not None else -math.pi)
            hi.append(j["upper"] if j["upper"] is not None else math.pi)
        return np.array(lo), np.array(hi)

    def fk(self, qs):
        """Link frames for a batch of configurations: {link: (N,4,4)} in the world."""
        qs = np.atleast_2d(np.asarray(qs, dtype=float))
        n = len(qs)
        frames = {self.root: np.broadcast_to(self.base_tf, (n, 4, 4)).copy()}
        for j in self.joints:
            t = frames[j["parent"]] @ j["origin"]
            if j["type"] in ("revolute", "continuous"):
                a = qs[:, self.index[j["name"]]]
                m = np.zeros((n, 4, 4))
                # Rodrigues: I + sin(a) K + (1 - cos(a)) K^2, K the axis' cross-product matrix
                m[:, :3, :3] = _I3 + np.sin(a)[:, None, None] * j["K"] + (1 - np.cos(a))[:, None, None] * j["K2"]
                m[:, 3, 3] = 1.0
                t = t @ m
            frames[j["child"]] = t
        return frames


def segment_steps(robot, qa, qb, max_joint_step=0.005, max_vertex_step=0.001):
    """Number of equal sub-steps for the straight segment qa -> qb so that no joint moves more
    than max_joint_step rad and no collision vertex more than max_vertex_step m per step."""
    d = np.abs(np.asarray(qb, dtype=float) - np.asarray(qa, dtype=float))
    n_joint = d.max() / max_joint_step
    n_vertex = float(d @ robot.radius_bound) / max_vertex_step
    return max(1, int(math.ceil(max(n_joint, n_vertex))))


def densify(robot, path, **kw):
    """Samples along a piecewise-linear joint path: (N,d) configurations and, per sample, the
    path parameter (segment index + fraction)."""
    path = np.asarray(path, dtype=float)
    qs, ts = [path[:1]], [np.zeros(1)]
    for i in range(len(path) - 1):
        n = segment_steps(robot, path[i], path[i + 1], **kw)
        f = np.arange(1, n + 1) / n
        qs.append(path[i][None] + f[:, None] * (path[i + 1] - path[i])[None])
        ts.append(i + f)
    return np.vstack(qs), np.concatenate(ts)


# ---------------------------------------------------------------- FCL model


def _fcl():
    import fcl
    return fcl


def obstacle_tf(o):
    return make_tf(o["pose"]["xyz"], quat_matrix(o["pose"]["quat_xyzw"]))


def obstacle_radius(o):
    if o["shape"] == "box":
        return float(np.linalg.norm(o["half_extents"]))
    if o["shape"] == "cylinder":
        return math.hypot(o["radius"], o["length"] / 2)
    if o["shape"] == "sphere":
        return float(o["radius"])
    raise ValueError(o["shape"])


def obstacle_half_box(o):
    """Half extents of a box in the obstacle's frame that contains it."""
    if o["shape"] == "box":
        return [float(h) for h in o["half_extents"]]
    if o["shape"] == "cylinder":
        return [o["radius"], o["radius"], o["length"] / 2]
    if o["shape"] == "sphere":
        return [o["radius"]] * 3
    raise ValueError(o["shape"])


def point_depth(o, pts):
    """Depth of points (in the obstacle's frame) inside a primitive: >0 inside (distance to the
    surface), <=0 outside."""
    if o["shape"] == "box":
        h = np.asarray(o["half_extents"])
        return (h[None] - np.abs(pts)).min(axis=1)
    if o["shape"] == "cylinder":
        rho = np.linalg.norm(pts[:, :2], axis=1)
        return np.minimum(o["radius"] - rho, o["length"] / 2 - np.abs(pts[:, 2]))
    if o["shape"] == "sphere":
        return o["radius"] - np.linalg.norm(pts, axis=1)
    raise ValueError(o["shape"])


class CollisionModel:
    """The robot's URDF collision geometry and a problem's primitive obstacles in FCL."""

    def __init__(self, robot, obstacles, margin=0.0):
        if margin != 0.0:
            raise NotImplementedError("margin != 0 (the MBM problems all have margin 0)")
        fcl = _fcl()
        self.fcl = fcl
        self.robot = robot
        self.obstacles = obstacles
        self.link_objs = {}  # link -> [(fcl.CollisionObject, geom origin 4x4, Geom)]
        for l in robot.collision_links:
            objs = []
            for g in robot.links[l]:
                objs.append((fcl.CollisionObject(self._robot_geometry(g)), g.origin, g))
            self.link_objs[l] = objs
        self.obs_objs = []
        for o in obstacles:
            tf = obstacle_tf(o)
            obj = fcl.CollisionObject(self._obstacle_geometry(o), fcl.Transform(tf[:3, :3], tf[:3, 3]))
            self.obs_objs.append(obj)
        self.obs_tf = [obstacle_tf(o) for o in obstacles]
        self.obs_center = np.array([t[:3, 3] for t in self.obs_tf]).reshape(-1, 3)
        self.obs_radius = np.array([obstacle_radius(o) for o in obstacles])
        self.obs_rot = np.array([t[:3, :3] for t in self.obs_tf]).reshape(-1, 3, 3)
        self.links = list(robot.collision_links)
        self.link_c = np.array([robot.sphere[l][0] for l in self.links])
        self.link_r = np.array([robot.sphere[l][1] for l in self.links])
        index = {l: i for i, l in enumerate(self.links)}
        self.pair_a = np.array([index[a] for a, _ in robot.moving_pairs], dtype=int)
        self.pair_b = np.array([index[b] for _, b in robot.moving_pairs], dtype=int)
        self.pair_r = self.link_r[self.pair_a] + self.link_r[self.pair_b]
        self.obs_half = np.array([obstacle_half_box(o) for o in obstacles]).reshape(-1, 3)
        self.req = fcl.CollisionRequest()
        self.req_contacts = fcl.CollisionRequest(num_max_contacts=1000, enable_contact=True)
        # pairs within one rigid body (fixed joints only) are checked once, here
        frames = robot.fk(np.zeros((1, len(robot.active))))
        self.rigid_contacts = []
        for a, b in robot.rigid_pairs:
            self._place(a, frames[a][0])
            self._place(b, frames[b][0])
            if self.collides_self(a, b):
                self.rigid_contacts.append(("self", a, b, self.self_depth(a, b), None))

    def _robot_geometry(self, g):
        fcl = self.fcl
        if g.kind == "mesh":
            # one BVH per mesh, shared by every model of the same Robot
            if getattr(g, "bvh", None) is None:
                m = fcl.BVHModel()
                m.beginModel(len(g.verts), len(g.faces))
                m.addSubModel(g.verts, g.faces)
                m.endModel()
                g.bvh = m
            return g.bvh
        if g.kind == "box":
            return fcl.Box(*(2 * g.half))
        if g.kind == "cylinder":
            return fcl.Cylinder(g.radius, g.length)
        if g.kind == "sphere":
            return fcl.Sphere(g.radius)
        raise ValueError(g.kind)

    def _obstacle_geometry(self, o):
        fcl = self.fcl
        if o["shape"] == "box":
            return fcl.Box(*(2 * np.asarray(o["half_extents"], dtype=float)))
        if o["shape"] == "cylinder":
            # FCL's cylinder: axis = local z, centred on the origin, like the problem format
            return fcl.Cylinder(float(o["radius"]), float(o["length"]))
        if o["shape"] == "sphere":
            return fcl.Sphere(float(o["radius"]))
        raise ValueError(o["shape"])

    def _place(self, link, tf):
        for obj, origin, _ in self.link_objs[link]:
            t = tf @ origin
            obj.setTransform(self.fcl.Transform(t[:3, :3], t[:3, 3]))

    def candidates(self, frames):
        """Broad phase for a batch, all links at once: env (N, links, obstacles) is True where the
        link's bounding sphere reaches the obstacle's bounding box; selfc (N, moving pairs) where
        the two links' spheres overlap. Conservative: FCL decides every candidate."""
        f = np.stack([frames[l] for l in self.links], axis=1)  # (N, L, 4, 4)
        w = np.einsum("nlij,lj->nli", f[:, :, :3, :3], self.link_c) + f[:, :, :3, 3]
        if len(self.obstacles):
            p = np.einsum("nlkj,kji->nlki", w[:, :, None, :] - self.obs_center[None, None], self.obs_rot)
            gap = np.maximum(np.abs(p) - self.obs_half[None, None], 0.0)
            env = np.sqrt((gap * gap).sum(axis=3)) <= self.link_r[None, :, None] + 1e-9
        else:
            env = np.zeros((len(w), len(self.links), 0), dtype=bool)
        if len(self.pair_a):
            d = w[:, self.pair_a] - w[:, self.pair_b]
            selfc = np.sqrt((d * d).sum(axis=2)) <= self.pair_r[None] + 1e-9
        else:
            selfc = np.zeros((len(w), 0), dtype=bool)
        return env, selfc

    def collides_env(self, link, k):
        for obj, _, _ in self.link_objs[link]:
            res = self.fcl.CollisionResult()
            if self.fcl.collide(obj, self.obs_objs[k], self.req, res):
                return True
        return False

    def collides_self(self, a, b):
        for oa, _, _ in self.link_objs[a]:
            for ob, _, _ in self.link_objs[b]:
                res = self.fcl.CollisionResult()
                if self.fcl.collide(oa, ob, self.req, res):
                    return True
        return False

    def env_depth(self, link, k, frame):
        """Penetration of link into obstacle k at a link frame: (FCL's largest contact
        penetration_depth, the deepest surface sample of the link's collision geometry inside
        the obstacle). The second samples each mesh at its vertices, edge midpoints and face
        centroids: a lower bound on how far the link's surface enters the obstacle, and never
        more than the obstacle's half thickness. FCL's depth is per triangle (EPA between one
        triangle and the primitive) and can exceed the obstacle's size when a large triangle
        cuts through a thin board."""
        fcl_depth = 0.0
        vdepth = 0.0
        inv = np.linalg.inv(self.obs_tf[k])
        for obj, origin, g in self.link_objs[link]:
            res = self.fcl.CollisionResult()
            if self.fcl.collide(obj, self.obs_objs[k], self.req_contacts, res):
                if res.contacts:
                    fcl_depth = max(fcl_depth, max(c.penetration_depth for c in res.contacts))
                t = inv @ frame
                pts = g.surface @ t[:3, :3].T + t[:3, 3]
                vdepth = max(vdepth, float(point_depth(self.obstacles[k], pts).max()))
        return fcl_depth, vdepth

    def self_depth(self, a, b):
        depth = 0.0
        for oa, _, _ in self.link_objs[a]:
            for ob, _, _ in self.link_objs[b]:
                res = self.fcl.CollisionResult()
                if self.fcl.collide(oa, ob, self.req_contacts, res) and res.contacts:
                    depth = max(depth, max(c.penetration_depth for c in res.contacts))
        return depth

    def check_batch(self, qs, stop_at_first=False, with_depth=True):
        """Exact check of configurations qs (N,d). Returns a list of per-sample contact lists;
        a contact is (kind, link, other, fcl_depth, vertex_depth) with kind 'env' or 'self'.
        Contacts between links of one rigid body (self.rigid_contacts, configuration-independent)
        are reported at every sample."""
        qs = np.atleast_2d(qs)
        frames = self.robot.fk(qs)
        env, selfc = self.candidates(frames)
        out = [list(self.rigid_contacts) for _ in range(len(qs))]
        if stop_at_first and self.rigid_contacts:
            return out
        rows = env.any(axis=(1, 2)) | selfc.any(axis=1)
        pairs = self.robot.moving_pairs
        for i in np.nonzero(rows)[0]:
            placed = set()

            def place(l):
                if l not in placed:
                    self._place(l, frames[l][i])
                    placed.add(l)

            for li, k in zip(*np.nonzero(env[i])):
                l = self.links[li]
                place(l)
                if self.collides_env(l, k):
                    if with_depth:
                        fd, vd = self.env_depth(l, k, frames[l][i])
                    else:
                        fd, vd = None, None
                    out[i].append(("env", l, self.obstacles[k].get("name", str(k)), fd, vd))
                    if stop_at_first:
                        break
            if not (stop_at_first and out[i]):
                for pi in np.nonzero(selfc[i])[0]:
                    a, b = pairs[pi]
                    place(a)
                    place(b)
                    if self.collides_self(a, b):
                        d = self.self_depth(a, b) if with_depth else None
                        out[i].append(("self", a, b, d, None))
                        if stop_at_first:
                            break
            if stop_at_first and out[i]:
                break
        return out

    def valid(self, q):
        """One configuration: True if no link touches an obstacle or a non-excluded link."""
        return not self.check_batch(np.asarray(q, dtype=float)[None], stop_at_first=True, with_depth=False)[0]
