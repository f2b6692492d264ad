// A driver for Geometric Tools' header-only AdaptiveSkeletonClimbing3 (Boost licence), built by
// run.sh from a fetched GTE checkout: the baseline that docs/adaptive.md compares against. It is
// not part of the project's build.
//
// Usage: asc_bench VOLUME.raw u8|i16|u16|i32 N ISO [DEPTH] [REPEATS]
//   VOLUME.raw holds (2^N+1)^3 samples, x fastest, little-endian (run.sh writes such crops).
//   ISO must not equal a sample value (GTE refuses one); DEPTH is GTE's `depth` (-1: no limit
//   on box size; d > 0 caps boxes at 2^(N-d)). Prints one JSON object.
//
// Time is measured as GTE's sample program uses the class: Extract, MakeUnique (vertex
// deduplication through std::map) and OrientTriangles (winding fixed from the gradient); the
// best of REPEATS runs. The checks read the final mesh only.

#include <Mathematics/AdaptiveSkeletonClimbing3.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iostream>
#include <map>
#include <set>
#include <string>
#include <unordered_map>
#include <vector>

using Real = double;
using Climb = gte::AdaptiveSkeletonClimbing3<int32_t, Real>;

static std::vector<int32_t> read_raw(char const* path, std::string const& dtype, size_t count)
{
    size_t width = dtype == "u8" ? 1 : (dtype == "i16" || dtype == "u16") ? 2 : 4;
    std::ifstream in(path, std::ios::binary);
    if (!in)
    {
        throw std::runtime_error(std::string("cannot open ") + path);
    }
    std::vector<unsigned char> bytes(count * width);
    in.read(reinterpret_cast<char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
    if (static_cast<size_t>(in.gcount()) != bytes.size())
    {
        throw std::runtime_error(std::string(path) + " is shorter than (2^N+1)^3 samples");
    }
    std::vector<int32_t> out(count);
    for (size_t i = 0; i < count; ++i)
    {
        unsigned char const* b = &bytes[i * width];
        if (dtype == "u8")
        {
            out[i] = b[0];
        }
        else if (dtype == "i16")
        {
            out[i] = static_cast<int16_t>(b[0] | (b[1] << 8));
        }
        else if (dtype == "u16")
        {
            out[i] = static_cast<uint16_t>(b[0] | (b[1] << 8));
        }
        else
        {
            uint32_t v = b[0] | (b[1] << 8) | (b[2] << 16) | (static_cast<uint32_t>(b[3]) << 24);
            out[i] = static_cast<int32_t>(v);
        }
    }
    return out;
}

struct Checks
{
    size_t degenerate = 0;       // a repeated vertex index
    size_t duplicates = 0;       // the same three vertices as another triangle, either winding
    size_t edges = 0;            // undirected edges
    size_t boundary = 0;         // edges in one triangle
    size_t nonManifold = 0;      // edges in three or more triangles
    size_t misoriented = 0;      // edges in two triangles that run the same way in both
    size_t badVertexLinks = 0;   // vertices whose triangles do not form one closed fan
    long long euler = 0;         // V - E + F
};

static Checks check(size_t numVertices, std::vector<gte::TriangleKey<true>> const& tris)
{
    Checks c;
    std::set<std::array<int32_t, 3>> seen;
    // Directed edge counts per undirected edge: (forward a<b, backward).
    std::map<std::pair<int32_t, int32_t>, std::array<int32_t, 2>> edges;
    std::vector<std::vector<std::pair<int32_t, int32_t>>> link(numVertices);
    for (auto const& t : tris)
    {
        int32_t v[3] = { t.V[0], t.V[1], t.V[2] };
        if (v[0] == v[1] || v[1] == v[2] || v[0] == v[2])
        {
            ++c.degenerate;
            continue;
        }
        std::array<int32_t, 3> key = { v[0], v[1], v[2] };
        std::sort(key.begin(), key.end());
        if (!seen.insert(key).second)
        {
            ++c.duplicates;
        }
        for (int i = 0; i < 3; ++i)
        {
            int32_t a = v[i], b = v[(i + 1) % 3];
            auto& e = edges[{ std::min(a, b), std::max(a, b) }];
            ++e[a < b ? 0 : 1];
            // The link of v[i] gets the edge between the triangle's other two vertices.
            link[v[i]].push_back({ v[(i + 1) % 3], v[(i + 2) % 3] });
        }
    }
    c.edges = edges.size();
    for (auto const& kv : edges)
    {
        int32_t n = kv.second[0] + kv.second[1];
        if (n == 1)
        {
            ++c.boundary;
        }
        else if (n > 2)
        {
            ++c.nonManifold;
        }
        else if (kv.second[0] != 1)
        {
            ++c.misoriented;
        }
    }
    // A vertex of a closed 2-manifold has a link that is one cycle: every link vertex in exactly
    // two link edges, and all link edges connected.
    for (auto const& l : link)
    {
        if (l.empty())
        {
            continue;
        }
        std::unordered_map<int32_t, std::vector<int32_t>> adj;
        for (auto const& e : l)
        {
            adj[e.first].push_back(e.second);
            adj[e.second].push_back(e.first);
        }
        bool ok = true;
        for (auto const& kv : adj)
        {
            ok = ok && kv.second.size() == 2;
        }
        if (ok)
        {
            // Walk the cycle from one link vertex; it must visit them all.
            int32_t start = adj.begin()->first, prev = -1, cur = start;
            size_t steps = 0;
            do
            {
                auto const& n = adj[cur];
                int32_t next = n[0] != prev ? n[0] : n[1];
                prev = cur;
                cur = next;
                ++steps;
            } while (cur != start && steps <= adj.size());
            ok = steps == adj.size();
        }
        if (!ok)
        {
            ++c.badVertexLinks;
        }
    }
    c.euler = static_cast<long long>(numVertices) - static_cast<long long>(c.edges)
        + static_cast<long long>(tris.size());
    return c;
}

int main(int argc, char** argv)
{
    if (argc < 5)
    {
        std::fprintf(stderr, "usage: %s VOLUME.raw u8|i16|u16|i32 N ISO [DEPTH] [REPEATS]\n", argv[0]);
        return 2;
    }
    try
    {
        std::string dtype = argv[2];
        int32_t N = std::stoi(argv[3]);
        Real iso = std::stod(argv[4]);
        int32_t depth = argc > 5 ? std::stoi(argv[5]) : -1;
        int repeats = argc > 6 ? std::stoi(argv[6]) : 3;
        if (N < 1 || N > 9 || repeats < 1)
        {
            throw std::runtime_error("N must be 1..9 and REPEATS at least 1");
        }
        size_t side = (size_t(1) << N) + 1;
        std::vector<int32_t> voxels = read_raw(argv[1], dtype, side * side * side);
        for (int32_t v : voxels)
        {
            if (static_cast<Real>(v) == iso)
            {
                throw std::runtime_error("ISO equals a sample value; GTE refuses that");
            }
        }

        double best = 1e300, bestExtract = 0.0;
        std::vector<std::array<Real, 3>> vertices;
        std::vector<gte::TriangleKey<true>> triangles;
        size_t rawTriangles = 0;
        for (int r = 0; r < repeats; ++r)
        {
            auto t0 = std::chrono::steady_clock::now();
            Climb climb(N, voxels.data());
            climb.Extract(iso, depth, vertices, triangles);
            auto t1 = std::chrono::steady_clock::now();
            rawTriangles = triangles.size();
            climb.MakeUnique(vertices, triangles);
            // false: wind against the gradient, outward from the samples above ISO, as GTE's
            // sample does and as the project's SPEC §7 asks.
            climb.OrientTriangles(vertices, triangles, false);
            auto t2 = std::chrono::steady_clock::now();
            double total = std::chrono::duration<double>(t2 - t0).count();
            if (total < best)
            {
                best = total;
                bestExtract = std::chrono::duration<double>(t1 - t0).count();
            }
        }

        Checks c = check(vertices.size(), triangles);
        bool closed = c.boundary == 0 && c.nonManifold == 0;
        std::printf(
            "{\"triangles\": %zu, \"triangles_before_make_unique\": %zu, \"vertices\": %zu, "
            "\"seconds\": %.4f, \"seconds_extract\": %.4f, "
            "\"closed\": %s, \"boundary_edges\": %zu, \"nonmanifold_edges\": %zu, "
            "\"misoriented_edges\": %zu, \"bad_vertex_links\": %zu, \"degenerate\": %zu, "
            "\"duplicate_triangles\": %zu, \"euler\": %lld}\n",
            triangles.size(), rawTriangles, vertices.size(), best, bestExtract,
            closed ? "true" : "false", c.boundary, c.nonManifold, c.misoriented,
            c.badVertexLinks, c.degenerate, c.duplicates, c.euler);
        return 0;
    }
    catch (std::exception const& e)
    {
        std::fprintf(stderr, "asc_bench: %s\n", e.what());
        return 1;
    }
}
