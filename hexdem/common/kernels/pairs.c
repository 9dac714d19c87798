/* The pairs of points within a distance of each other, by a cell list (see kernels.h). */
#include <math.h>
#include <stdlib.h>

#include "kernels.h"

/* A point's square cell, `cutoff` wide, and its index. */
typedef struct {
    int64_t y, x, point;
} Entry;

static int by_cell(const void *a, const void *b)
{
    const Entry *p = a, *q = b;
    if (p->y != q->y)
        return p->y < q->y ? -1 : 1;
    if (p->x != q->x)
        return p->x < q->x ? -1 : 1;
    return (p->point > q->point) - (p->point < q->point);
}

/* The first of the m sorted entries at or after cell (y, x), by bisection. */
static int64_t first_at(const Entry *entries, int64_t m, int64_t y, int64_t x)
{
    int64_t low = 0, high = m;
    while (low < high) {
        int64_t mid = low + (high - low) / 2;
        if (entries[mid].y < y || (entries[mid].y == y && entries[mid].x < x))
            low = mid + 1;
        else
            high = mid;
    }
    return low;
}

/* The entries of cell (y, x) among the m sorted ones: range[0] to range[1] − 1 (none: equal). */
static void cell_range(const Entry *entries, int64_t m, int64_t y, int64_t x, int64_t range[2])
{
    range[0] = first_at(entries, m, y, x);
    for (range[1] = range[0]; range[1] < m && entries[range[1]].y == y && entries[range[1]].x == x;)
        range[1]++;
}

int64_t pairs_within(int64_t n, const double *positions, double cutoff, int64_t capacity, int64_t *i, int64_t *j)
{
    double low[2] = {INFINITY, INFINITY}, high[2] = {-INFINITY, -INFINITY};
    for (int64_t r = 0; r < n; r++)
        for (int a = 0; a < 2; a++) {
            double x = positions[2 * r + a];
            if (!isfinite(x))
                return -2;
            low[a] = x < low[a] ? x : low[a];
            high[a] = x > high[a] ? x : high[a];
        }
    if (n == 0)
        return 0;
    /* cells as wide as the cutoff (wider where the packing spans more than 2^52 of them) */
    double width = cutoff > 0.0 ? cutoff : 1.0;
    if (!isfinite(high[0] - low[0]) || !isfinite(high[1] - low[1]) || !isfinite(width))
        return -2; /* (a span beyond the largest double) */
    while ((high[0] - low[0]) / width > 0x1p52 || (high[1] - low[1]) / width > 0x1p52)
        width *= 2.0;
    Entry *entries = malloc(sizeof(Entry) * (size_t)n);
    if (entries == NULL)
        return -1;
    for (int64_t r = 0; r < n; r++) {
        entries[r].x = (int64_t)((positions[2 * r] - low[0]) / width);
        entries[r].y = (int64_t)((positions[2 * r + 1] - low[1]) / width);
        entries[r].point = r;
    }
    qsort(entries, (size_t)n, sizeof(Entry), by_cell);
    const double limit = cutoff * cutoff;
    /* each point with those after it in its cell, and with the cells ahead: right, and the three
     * above, whose entries are found once a cell */
    static const int64_t ahead[4][2] = {{0, 1}, {1, -1}, {1, 0}, {1, 1}};
    int64_t found = 0, own[2] = {0, 0}, near[4][2];
    for (int64_t p = 0; p < n; p++) {
        if (p == own[1]) {
            int64_t y = entries[p].y, x = entries[p].x;
            cell_range(entries, n, y, x, own);
            for (int k = 0; k < 4; k++)
                cell_range(entries, n, y + ahead[k][0], x + ahead[k][1], near[k]);
        }
        int64_t a = entries[p].point;
        for (int k = -1; k < 4; k++) {
            int64_t q = k < 0 ? p + 1 : near[k][0], last = k < 0 ? own[1] : near[k][1];
            for (; q < last; q++) {
                int64_t b = entries[q].point;
                double dx = positions[2 * a] - positions[2 * b], dy = positions[2 * a + 1] - positions[2 * b + 1];
                if (dx * dx + dy * dy <= limit) {
                    if (found < capacity) {
                        i[found] = a < b ? a : b;
                        j[found] = a < b ? b : a;
                    }
                    found++;
                }
            }
        }
    }
    free(entries);
    return found;
}
