#include "core/clip.h"

#include <glm/matrix.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <vector>

#include "core/number.h"

namespace isowall {

bool ClipSet::add(const ClipPlane& p) {
    if (count == kMaxClipPlanes) return false;
    planes[count++] = p;
    return true;
}

bool ClipSet::keeps(glm::vec3 p) const {
    return std::all_of(begin(), end(), [p](const ClipPlane& c) { return c.side(p) >= 0; });
}

bool operator==(const ClipSet& a, const ClipSet& b) {
    return a.count == b.count && std::equal(a.begin(), a.end(), b.begin());
}

std::ostream& operator<<(std::ostream& os, const ClipSet& c) {
    return os << "clip{" << clip_text(c) << "}";
}

std::string clip_text(const ClipSet& clip) {
    std::string out;
    for (const ClipPlane& p : clip) {
        if (!out.empty()) out += ' ';
        out += clip_plane_text(p);
    }
    return out;
}

ClipSet in_object_space(const ClipSet& voxel, glm::vec3 spacing) {
    ClipSet out;
    for (const ClipPlane& p : voxel) {
        // dot(n, o / s) >= at  <=>  dot(n / s, o) >= at, scaled to a unit normal.
        const glm::vec3 n = p.normal / spacing;
        const float len = glm::length(n);
        out.add({n / len, p.at / len});
    }
    return out;
}

namespace {

// The corner of `box` farthest along `n` (`far`), or least far.
glm::vec3 corner_along(const Box3& box, glm::vec3 n, bool far) {
    glm::vec3 c;
    for (int a = 0; a < 3; ++a) c[a] = (n[a] >= 0) == far ? box.max[a] : box.min[a];
    return c;
}

}  // namespace

bool cut_away(const ClipSet& clip, const Box3& box) {
    // A plane cuts the whole box away when even the corner farthest along its normal is cut.
    return std::any_of(clip.begin(), clip.end(), [&box](const ClipPlane& p) {
        return p.side(corner_along(box, p.normal, true)) < 0;
    });
}

bool keeps_whole(const ClipSet& clip, const Box3& box) {
    // Every plane keeps the whole box when it keeps even the corner least far along its normal.
    return std::all_of(clip.begin(), clip.end(), [&box](const ClipPlane& p) {
        return p.side(corner_along(box, p.normal, false)) >= 0;
    });
}

bool keeps_some_voxel(const ClipSet& clip, glm::ivec3 dims) {
    const glm::dvec3 hi(glm::max(dims - 1, glm::ivec3(0)));
    struct Half {
        glm::dvec3 n;
        double at;
    };
    std::vector<Half> all;  // the box's six faces, then the planes: keeps dot(n, p) >= at
    for (int a = 0; a < 3; ++a) {
        glm::dvec3 n(0);
        n[a] = 1;
        all.push_back({n, 0});
        all.push_back({-n, -hi[a]});
    }
    for (const ClipPlane& p : clip) all.push_back({glm::dvec3(p.normal), double(p.at)});
    const double eps = 1e-6 * (1 + std::max({hi.x, hi.y, hi.z}));
    auto inside = [&](const glm::dvec3& q) {
        return std::all_of(all.begin(), all.end(),
                           [&](const Half& h) { return glm::dot(h.n, q) - h.at >= -eps; });
    };
    for (std::size_t i = 0; i < all.size(); ++i)
        for (std::size_t j = i + 1; j < all.size(); ++j)
            for (std::size_t k = j + 1; k < all.size(); ++k) {
                // The rows of the system are the three normals (glm's matrices are by columns).
                const glm::dmat3 m = glm::transpose(glm::dmat3(all[i].n, all[j].n, all[k].n));
                if (std::abs(glm::determinant(m)) < 1e-12) continue;
                if (inside(glm::inverse(m) * glm::dvec3(all[i].at, all[j].at, all[k].at)))
                    return true;
            }
    return false;
}

std::optional<RaySpan> kept_span(const ClipSet& clip, const Ray& ray) {
    RaySpan s{0, std::numeric_limits<float>::infinity()};
    for (const ClipPlane& p : clip) {
        const float at_origin = p.side(ray.o);
        const float rate = glm::dot(p.normal, ray.d);
        if (rate == 0) {
            if (at_origin < 0) return std::nullopt;  // parallel, on the cut side
            continue;
        }
        const float t = -at_origin / rate;  // where the ray crosses the plane
        if (rate > 0)
            s.t0 = std::max(s.t0, t);  // entering the kept side
        else
            s.t1 = std::min(s.t1, t);  // leaving it
    }
    if (s.t0 > s.t1) return std::nullopt;
    return s;
}

std::optional<ClippedRay> clip_ray(const ClipSet& clip, const Ray& ray) {
    constexpr float kFar = std::numeric_limits<float>::max();
    if (clip.empty()) return ClippedRay{ray, kFar};
    const auto s = kept_span(clip, ray);
    if (!s) return std::nullopt;
    return ClippedRay{{ray.at(s->t0), ray.d}, std::isinf(s->t1) ? kFar : s->t1 - s->t0};
}

namespace {

struct Corner {
    glm::vec3 position, normal, colour;
};

// Sutherland-Hodgman: the part of convex polygon `in` on the kept side of `plane`.
void clip_polygon(const std::vector<Corner>& in, const ClipPlane& plane, std::vector<Corner>& out) {
    out.clear();
    for (std::size_t i = 0; i < in.size(); ++i) {
        const Corner& a = in[i];
        const Corner& b = in[(i + 1) % in.size()];
        const float da = plane.side(a.position), db = plane.side(b.position);
        if (da >= 0) out.push_back(a);
        if ((da >= 0) != (db >= 0)) {
            const float t = da / (da - db);
            const glm::vec3 n = a.normal + t * (b.normal - a.normal);
            const float len = glm::length(n);
            out.push_back({a.position + t * (b.position - a.position), len > 0 ? n / len : a.normal,
                           a.colour + t * (b.colour - a.colour)});
        }
    }
}

}  // namespace

void clip_mesh(Mesh& mesh, const ClipSet& clip) {
    if (clip.empty() || mesh.empty()) return;
    const std::size_t n = mesh.vertex_count();
    std::vector<std::uint8_t> kept(n);
    for (std::size_t v = 0; v < n; ++v) kept[v] = clip.keeps(mesh.positions[v]) ? 1 : 0;
    const bool normals = mesh.normals.size() == n;
    const bool colours = mesh.colours.size() == n;
    Mesh out;
    std::vector<std::uint32_t> index(n, UINT32_MAX);  // old vertex -> new
    auto keep_vertex = [&](std::uint32_t v) {
        if (index[v] == UINT32_MAX) {
            index[v] = static_cast<std::uint32_t>(out.positions.size());
            out.positions.push_back(mesh.positions[v]);
            if (normals) out.normals.push_back(mesh.normals[v]);
            if (colours) out.colours.push_back(mesh.colours[v]);
        }
        out.indices.push_back(index[v]);
    };
    std::vector<Corner> poly, next;
    for (std::size_t t = 0; t + 2 < mesh.indices.size(); t += 3) {
        const std::uint32_t* tri = &mesh.indices[t];
        const int inside = kept[tri[0]] + kept[tri[1]] + kept[tri[2]];
        if (inside == 3) {
            for (int k = 0; k < 3; ++k) keep_vertex(tri[k]);
            continue;
        }
        poly.clear();
        for (int k = 0; k < 3; ++k)
            poly.push_back({mesh.positions[tri[k]], normals ? mesh.normals[tri[k]] : glm::vec3(0),
                            colours ? glm::vec3(mesh.colours[tri[k]]) : glm::vec3(0)});
        for (const ClipPlane& p : clip) {
            clip_polygon(poly, p, next);
            poly.swap(next);
            if (poly.size() < 3) break;
        }
        if (poly.size() < 3) continue;
        // A fan over the kept polygon (convex, in the triangle's winding).
        const auto first = static_cast<std::uint32_t>(out.positions.size());
        for (const Corner& c : poly) {
            out.positions.push_back(c.position);
            if (normals) out.normals.push_back(c.normal);
            if (colours) out.colours.push_back(glm::u8vec3(glm::round(c.colour)));
        }
        for (std::uint32_t k = 1; k + 1 < poly.size(); ++k)
            out.indices.insert(out.indices.end(), {first, first + k, first + k + 1});
    }
    mesh = std::move(out);
}

namespace {

// Voxel indices and plane coefficients beyond this are no volume's (and would overflow a float).
constexpr double kMaxClipNumber = 1e6;

bool clip_number(const std::optional<double>& x) {
    return x && std::abs(*x) <= kMaxClipNumber;
}

std::string_view trim(std::string_view s) {
    while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
    while (!s.empty() && (s.back() == ' ' || s.back() == '\t')) s.remove_suffix(1);
    return s;
}

}  // namespace

std::optional<ClipPlane> parse_clip_plane(std::string_view text, std::string& problem) {
    const std::string_view t = trim(text);
    const std::size_t op = t.find_first_of("<>");
    if (op == std::string_view::npos || t.find_first_of("<>", op + 1) != std::string_view::npos) {
        problem = "expected x<N, y>N, z<N or A,B,C<D (one < or >), got '" + std::string(t) + "'";
        return std::nullopt;
    }
    const std::string_view lhs = trim(t.substr(0, op));
    const auto d = parse_number(trim(t.substr(op + 1)));
    if (!clip_number(d)) {
        problem = "expected a number in [-1e6, 1e6] after '" + std::string(1, t[op]) + "', got '" +
                  std::string(trim(t.substr(op + 1))) + "'";
        return std::nullopt;
    }
    glm::vec3 n{0};
    if (lhs == "x" || lhs == "y" || lhs == "z") {
        n[lhs[0] - 'x'] = 1;
    } else {
        std::size_t start = 0;
        for (int a = 0; a < 3; ++a) {
            const std::size_t comma = a < 2 ? lhs.find(',', start) : lhs.size();
            const auto c = comma == std::string_view::npos
                               ? std::nullopt
                               : parse_number(trim(lhs.substr(start, comma - start)));
            if (!clip_number(c)) {
                problem = "expected x, y, z or three numbers A,B,C in [-1e6, 1e6] before '" +
                          std::string(1, t[op]) + "', got '" + std::string(lhs) + "'";
                return std::nullopt;
            }
            n[a] = static_cast<float>(*c);
            start = comma + 1;
        }
    }
    const float len = glm::length(n);
    if (!(len > 0) || !std::isfinite(len)) {
        problem = "the plane's direction A,B,C is zero in '" + std::string(t) + "'";
        return std::nullopt;
    }
    // A,B,C > D keeps dot(n, p) >= D; A,B,C < D keeps dot(-n, p) >= -D.
    const float sign = t[op] == '>' ? 1.0f : -1.0f;
    return ClipPlane{sign * n / len, sign * static_cast<float>(*d) / len};
}

std::optional<ClipSet> clip_box(glm::vec3 lo, glm::vec3 hi, std::string& problem) {
    if (!(lo.x < hi.x && lo.y < hi.y && lo.z < hi.z)) {
        std::ostringstream os;
        os << "expected X0 < X1, Y0 < Y1 and Z0 < Z1, got " << lo.x << ',' << lo.y << ',' << lo.z
           << " - " << hi.x << ',' << hi.y << ',' << hi.z;
        problem = os.str();
        return std::nullopt;
    }
    ClipSet s;
    for (int a = 0; a < 3; ++a) {
        glm::vec3 n{0};
        n[a] = 1;
        s.add({n, lo[a]});
        s.add({-n, -hi[a]});
    }
    return s;
}

std::string clip_plane_text(const ClipPlane& plane) {
    std::ostringstream os;
    os.precision(9);  // a float's every digit: the text reads back to the same plane
    for (int a = 0; a < 3; ++a) {
        glm::vec3 axis{0};
        axis[a] = 1;
        if (plane.normal == axis || plane.normal == -axis) {
            const bool above = plane.normal[a] > 0;
            os << char('x' + a) << (above ? '>' : '<') << (above ? plane.at : -plane.at);
            return os.str();
        }
    }
    os << plane.normal.x << ',' << plane.normal.y << ',' << plane.normal.z << '>' << plane.at;
    return os.str();
}

}  // namespace isowall
