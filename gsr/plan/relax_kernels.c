/* Compiled h_add / relaxed plan / successor generation / landmark exploration for gsr.plan.
 *
 * Built on first use by gsr/plan/relax_c.py with the system's C compiler (cc -O2 -shared) and
 * loaded through ctypes: no numba, no numpy, loading takes milliseconds. Every array is owned by the
 * Python side (array.array buffers kept alive by the caller); the context only holds pointers.
 *
 * Same results as the Python path (gsr.plan.heuristics.Relaxation._hadd_buckets): the state's facts
 * are counted from scratch in the same order (atoms ascending, the always-true fact, the true
 * complement facts in complement order), and facts are popped by (cost, insertion order): FIFO
 * buckets for costs below max_buckets, a binary heap keyed by (cost, insertion order)
 * above it (every bucket entry pops before every heap entry, so the order is the same).
 */
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#define UNREACHED ((int64_t)1 << 62)

typedef struct {
    int64_t n_atoms, n_facts, n_unary, n_ops, true_fact, goal, stop, n_comp;
    const int64_t *comp_atom, *comp_fact;
    const int64_t *pre_of_ptr, *pre_of_idx, *add_ptr, *add_idx, *pre_ptr, *pre_idx;
    const int64_t *npre, *ucost, *owner;
    const int64_t *opre_ptr, *opre_idx, *oneg_ptr, *oneg_idx; /* operators' positive and negative atoms */
    int64_t *cost, *sup; /* results, read by Python */
    /* work buffers (malloc'd here) */
    int64_t *acc, *unsat, *first, *seen, *mark, *stack;
    int64_t stamp;
    int64_t n_buckets, max_buckets, *bhead, *btail; /* bucket table, grown up to max_buckets */
    int64_t *nfact, *nnext;            /* bucket nodes (one per push) */
    int64_t *hk, *hc, *hf;             /* overflow heap: (seq, cost, fact) */
    int64_t lifo;                      /* buckets above 0 last in first out (Fast Downward's order) */
} relax_t;

static void *alloc(int64_t n) { return malloc((size_t)(n > 0 ? n : 1) * sizeof(int64_t)); }

void gsr_relax_free(relax_t *r) {
    if (!r) return;
    free(r->acc); free(r->unsat); free(r->first); free(r->seen); free(r->mark); free(r->stack);
    free(r->bhead); free(r->btail); free(r->nfact); free(r->nnext);
    free(r->hk); free(r->hc); free(r->hf);
    free(r);
}

relax_t *gsr_relax_new(int64_t n_atoms, int64_t n_facts, int64_t n_unary, int64_t n_ops, int64_t true_fact,
                       int64_t goal, int64_t stop, int64_t n_comp, int64_t max_buckets, const int64_t *comp_atom,
                       const int64_t *comp_fact, const int64_t *pre_of_ptr, const int64_t *pre_of_idx,
                       const int64_t *add_ptr, const int64_t *add_idx, const int64_t *pre_ptr,
                       const int64_t *pre_idx, const int64_t *npre, const int64_t *ucost, const int64_t *owner,
                       int64_t *cost, int64_t *sup) {
    relax_t *r = calloc(1, sizeof(relax_t));
    if (!r) return NULL;
    r->n_atoms = n_atoms; r->n_facts = n_facts; r->n_unary = n_unary; r->n_ops = n_ops;
    r->true_fact = true_fact; r->goal = goal; r->stop = stop; r->n_comp = n_comp;
    r->comp_atom = comp_atom; r->comp_fact = comp_fact;
    r->pre_of_ptr = pre_of_ptr; r->pre_of_idx = pre_of_idx; r->add_ptr = add_ptr; r->add_idx = add_idx;
    r->pre_ptr = pre_ptr; r->pre_idx = pre_idx; r->npre = npre; r->ucost = ucost; r->owner = owner;
    r->cost = cost; r->sup = sup;
    int64_t pushes = add_ptr[n_unary] + n_facts + 1; /* each push lowers a fact's cost via one edge */
    r->acc = alloc(n_unary); r->unsat = alloc(n_unary); r->first = alloc(n_facts + 1);
    r->seen = calloc((size_t)n_facts + 1, sizeof(int64_t)); r->mark = calloc((size_t)n_ops + 1, sizeof(int64_t));
    r->stack = alloc(n_facts + 1);
    r->max_buckets = max_buckets > 1 ? max_buckets : 1;
    r->n_buckets = r->max_buckets < 1024 ? r->max_buckets : 1024;
    r->bhead = alloc(r->n_buckets); r->btail = alloc(r->n_buckets);
    r->nfact = alloc(pushes); r->nnext = alloc(pushes);
    r->hk = alloc(pushes); r->hc = alloc(pushes); r->hf = alloc(pushes);
    if (!r->acc || !r->unsat || !r->first || !r->seen || !r->mark || !r->stack || !r->bhead || !r->btail ||
        !r->nfact || !r->nnext || !r->hk || !r->hc || !r->hf) {
        gsr_relax_free(r);
        return NULL;
    }
    for (int64_t b = 0; b < r->n_buckets; b++) r->bhead[b] = -1;
    return r;
}

static void heap_push(int64_t *hk, int64_t *hc, int64_t *hf, int64_t size, int64_t c, int64_t k, int64_t f) {
    int64_t i = size;
    while (i > 0) {
        int64_t p = (i - 1) >> 1;
        if (hc[p] < c || (hc[p] == c && hk[p] < k)) break;
        hk[i] = hk[p]; hc[i] = hc[p]; hf[i] = hf[p];
        i = p;
    }
    hk[i] = k; hc[i] = c; hf[i] = f;
}

/* Removes the root; ``size`` is the size after removal. */
static void heap_pop(int64_t *hk, int64_t *hc, int64_t *hf, int64_t size) {
    int64_t k = hk[size], c = hc[size], f = hf[size], i = 0;
    for (;;) {
        int64_t left = 2 * i + 1;
        if (left >= size) break;
        int64_t m = left, right = left + 1;
        if (right < size && (hc[right] < hc[left] || (hc[right] == hc[left] && hk[right] < hk[left]))) m = right;
        if (hc[m] > c || (hc[m] == c && hk[m] > k)) break;
        hk[i] = hk[m]; hc[i] = hc[m]; hf[i] = hf[m];
        i = m;
    }
    hk[i] = k; hc[i] = c; hf[i] = f;
}

/* Buckets above cost 0 last in first out (1) or first in first out (0, the default). */
void gsr_relax_set_lifo(relax_t *r, int64_t lifo) { r->lifo = lifo; }

/* h_add of ``state`` (little-endian bitset bytes): fills cost (UNREACHED when unreached) and sup. Returns
 * 0, or -1 when the bucket table could not grow (out of memory). */
int64_t gsr_hadd(relax_t *r, const uint8_t *state, int64_t n_bytes) {
    int64_t *cost = r->cost, *sup = r->sup, *acc = r->acc, *unsat = r->unsat, *first = r->first;
    const int64_t *pre_of_ptr = r->pre_of_ptr, *pre_of_idx = r->pre_of_idx, *add_ptr = r->add_ptr,
                  *add_idx = r->add_idx;
    int64_t *bhead = r->bhead, *btail = r->btail, *nfact = r->nfact, *nnext = r->nnext;
    const int64_t stop = r->stop, goal = r->goal;
    for (int64_t f = 0; f < r->n_facts; f++) { cost[f] = UNREACHED; sup[f] = -1; }
    memcpy(acc, r->ucost, (size_t)r->n_unary * sizeof(int64_t));
    memcpy(unsat, r->npre, (size_t)r->n_unary * sizeof(int64_t));
    int64_t nfirst = 0;
    for (int64_t byte = 0; byte < n_bytes; byte++) {
        uint8_t b = state[byte];
        while (b) {
            int bit = __builtin_ctz(b);
            b &= (uint8_t)(b - 1);
            int64_t a = byte * 8 + bit;
            if (a < r->n_atoms) first[nfirst++] = a;
        }
    }
    first[nfirst++] = r->true_fact;
    for (int64_t j = 0; j < r->n_comp; j++) {
        int64_t a = r->comp_atom[j];
        int on = (a >> 3) < n_bytes ? (state[a >> 3] >> (a & 7)) & 1 : 0;
        if (!on) first[nfirst++] = r->comp_fact[j];
    }
    for (int64_t j = 0; j < nfirst; j++) cost[first[j]] = 0;
    int64_t top = -1;   /* highest bucket in use */
    int64_t nodes = 0;  /* bucket nodes used */
    int64_t hsize = 0, seq = 0;
    int64_t result = 0;
#define PUSH(V, G)                                                                        \
    do {                                                                                  \
        int64_t v_ = (V), g_ = (G);                                                       \
        if (v_ >= r->n_buckets && v_ < r->max_buckets) {                                     \
            int64_t nb = r->n_buckets;                                                    \
            while (nb <= v_) nb *= 2;                                                     \
            if (nb > r->max_buckets) nb = r->max_buckets;                                       \
            int64_t *h2 = realloc(bhead, (size_t)nb * sizeof(int64_t));                   \
            if (!h2) { result = -1; goto done; }                                          \
            bhead = r->bhead = h2;                                                        \
            int64_t *t2 = realloc(btail, (size_t)nb * sizeof(int64_t));                  \
            if (!t2) { result = -1; goto done; }                                          \
            btail = r->btail = t2;                                                        \
            for (int64_t b_ = r->n_buckets; b_ < nb; b_++) bhead[b_] = -1;                \
            r->n_buckets = nb;                                                            \
        }                                                                                 \
        if (v_ < r->n_buckets) {                                                          \
            nfact[nodes] = g_;                                                            \
            if (r->lifo && v_ > 0) { /* a stack: pushed at the head, popped from it */    \
                nnext[nodes] = bhead[v_];                                                 \
                bhead[v_] = nodes;                                                        \
            } else {                                                                      \
                nnext[nodes] = -1;                                                        \
                if (bhead[v_] < 0) bhead[v_] = nodes; else nnext[btail[v_]] = nodes;      \
                btail[v_] = nodes;                                                        \
            }                                                                             \
            nodes++;                                                                      \
            if (v_ > top) top = v_;                                                       \
        } else {                                                                          \
            heap_push(r->hk, r->hc, r->hf, hsize, v_, seq, g_);                           \
            hsize++;                                                                      \
        }                                                                                 \
        seq++;                                                                            \
    } while (0)
#define RELAX(U, V)                                                                       \
    do {                                                                                  \
        int64_t u__ = (U), v__ = (V);                                                     \
        for (int64_t q = add_ptr[u__]; q < add_ptr[u__ + 1]; q++) {                       \
            int64_t g = add_idx[q];                                                       \
            if (v__ < cost[g]) {                                                          \
                cost[g] = v__;                                                            \
                sup[g] = u__;                                                             \
                if (g == stop) goto done;                                                 \
                PUSH(v__, g);                                                             \
            }                                                                             \
        }                                                                                 \
    } while (0)
    for (int64_t j = 0; j < nfirst; j++) {
        int64_t f = first[j];
        for (int64_t e = pre_of_ptr[f]; e < pre_of_ptr[f + 1]; e++) {
            int64_t u = pre_of_idx[e];
            if (--unsat[u] == 0) RELAX(u, acc[u]);
        }
    }
    for (int64_t c = 0; c <= top; c++) {
        int pop = r->lifo && c > 0; /* LIFO: take the head off first; pushes land before the rest */
        for (int64_t node = bhead[c]; node >= 0;) { /* the bucket may grow */
            if (pop) bhead[c] = nnext[node];
            int64_t f = nfact[node];
            if (cost[f] == c) {
                if (f == goal) goto done;
                for (int64_t e = pre_of_ptr[f]; e < pre_of_ptr[f + 1]; e++) {
                    int64_t u = pre_of_idx[e];
                    acc[u] += c;
                    if (--unsat[u] == 0) RELAX(u, acc[u]);
                }
            }
            node = pop ? bhead[c] : nnext[node];
        }
    }
    while (hsize > 0) {
        int64_t c = r->hc[0], f = r->hf[0];
        hsize--;
        if (hsize > 0) heap_pop(r->hk, r->hc, r->hf, hsize);
        if (cost[f] != c) continue;
        if (f == goal) goto done;
        for (int64_t e = pre_of_ptr[f]; e < pre_of_ptr[f + 1]; e++) {
            int64_t u = pre_of_idx[e];
            acc[u] += c;
            if (--unsat[u] == 0) RELAX(u, acc[u]);
        }
    }
done:
    for (int64_t b = 0; b <= top && b < r->n_buckets; b++) bhead[b] = -1;
    return result;
#undef PUSH
#undef RELAX
}

/* Operators of the relaxed plan from the last gsr_hadd (each once, in discovery order); returns their
 * number. The goal must be reached. */
int64_t gsr_relaxed_plan(relax_t *r, int64_t *out) {
    int64_t stamp = ++r->stamp, n_out = 0, top = 0;
    int64_t *seen = r->seen, *mark = r->mark, *stack = r->stack;
    const int64_t *sup = r->sup, *owner = r->owner, *pre_ptr = r->pre_ptr, *pre_idx = r->pre_idx;
    seen[r->goal] = stamp;
    stack[top++] = r->goal;
    while (top > 0) {
        int64_t u = sup[stack[--top]];
        if (u < 0) continue;
        int64_t o = owner[u];
        if (o >= 0 && mark[o] != stamp) {
            mark[o] = stamp;
            out[n_out++] = o;
        }
        for (int64_t e = pre_ptr[u]; e < pre_ptr[u + 1]; e++) {
            int64_t g = pre_idx[e];
            if (seen[g] != stamp) {
                seen[g] = stamp;
                stack[top++] = g;
            }
        }
    }
    return n_out;
}

static int cmp_i64(const void *a, const void *b) {
    int64_t x = *(const int64_t *)a, y = *(const int64_t *)b;
    return (x > y) - (x < y);
}

/* Ascending: insertion sort of short lists, qsort of long ones. */
static void sort_i64(int64_t *out, int64_t n) {
    if (n > 64) {
        qsort(out, (size_t)n, sizeof(int64_t), cmp_i64);
        return;
    }
    for (int64_t i = 1; i < n; i++) {
        int64_t x = out[i], j = i - 1;
        while (j >= 0 && out[j] > x) { out[j + 1] = out[j]; j--; }
        out[j + 1] = x;
    }
}

/* The operators' atoms, for the preferred operators of gsr_ff (arrays owned by the caller). */
void gsr_relax_set_ops(relax_t *r, const int64_t *opre_ptr, const int64_t *opre_idx, const int64_t *oneg_ptr,
                       const int64_t *oneg_idx) {
    r->opre_ptr = opre_ptr; r->opre_idx = opre_idx; r->oneg_ptr = oneg_ptr; r->oneg_idx = oneg_idx;
}

/* h_FF of ``state``: the relaxed plan's operators go to ``out``, those applicable in ``state`` (the
 * preferred operators, ascending as the Python path returns them; their number in ``*n_pref``) first,
 * then the others in discovery order. Returns the
 * plan's size, or -1 when the goal is unreachable, -2 when out of memory. Needs gsr_relax_set_ops. */
int64_t gsr_ff(relax_t *r, const uint8_t *state, int64_t n_bytes, int64_t *out, int64_t *n_pref) {
    if (gsr_hadd(r, state, n_bytes) < 0) return -2;
    if (r->cost[r->goal] >= UNREACHED) return -1;
    int64_t n = gsr_relaxed_plan(r, out), k = 0;
    int64_t *rest = r->stack; /* free again after the plan walk */
    int64_t n_rest = 0;
#define HOLDS(A) ((A) >> 3 < n_bytes && (state[(A) >> 3] >> ((A) & 7)) & 1)
    for (int64_t j = 0; j < n; j++) {
        int64_t o = out[j], ok = 1;
        for (int64_t e = r->opre_ptr[o]; e < r->opre_ptr[o + 1] && ok; e++) if (!HOLDS(r->opre_idx[e])) ok = 0;
        for (int64_t e = r->oneg_ptr[o]; e < r->oneg_ptr[o + 1] && ok; e++) if (HOLDS(r->oneg_idx[e])) ok = 0;
        if (ok) out[k++] = o; else rest[n_rest++] = o;
    }
#undef HOLDS
    sort_i64(out, k);
    memcpy(out + k, rest, (size_t)n_rest * sizeof(int64_t));
    *n_pref = k;
    return n;
}

/* Landmarks' relaxed exploration from the facts ``first`` that never adds ``blocked``: ``reached`` (a
 * little-endian bitset of n_atoms bits, zeroed here) ends with the reached facts, ``blocked`` excluded. */
void gsr_reach_without(int64_t n_atoms, const int64_t *first, int64_t n_first, const int64_t *blocked,
                       int64_t n_blocked,
                       const int64_t *pre_of_ptr, const int64_t *pre_of_idx, const int64_t *add_ptr,
                       const int64_t *add_idx, const int64_t *npre, const int64_t *no_pre, int64_t n_no_pre,
                       int64_t *unsat, int64_t n_unary, uint8_t *seen, int64_t *queue, uint8_t *reached) {
    memcpy(unsat, npre, (size_t)n_unary * sizeof(int64_t));
    memset(seen, 0, (size_t)n_atoms);
    for (int64_t j = 0; j < n_blocked; j++) seen[blocked[j]] = 1;
    int64_t n = 0;
    for (int64_t j = 0; j < n_first; j++) {
        int64_t f = first[j];
        if (!seen[f]) { seen[f] = 1; queue[n++] = f; }
    }
    for (int64_t j = 0; j < n_no_pre; j++) {
        int64_t u = no_pre[j];
        for (int64_t q = add_ptr[u]; q < add_ptr[u + 1]; q++) {
            int64_t g = add_idx[q];
            if (!seen[g]) { seen[g] = 1; queue[n++] = g; }
        }
    }
    for (int64_t k = 0; k < n; k++) {
        int64_t f = queue[k];
        for (int64_t e = pre_of_ptr[f]; e < pre_of_ptr[f + 1]; e++) {
            int64_t u = pre_of_idx[e];
            if (--unsat[u] == 0) {
                for (int64_t q = add_ptr[u]; q < add_ptr[u + 1]; q++) {
                    int64_t g = add_idx[q];
                    if (!seen[g]) { seen[g] = 1; queue[n++] = g; }
                }
            }
        }
    }
    memset(reached, 0, (size_t)((n_atoms + 7) / 8));
    for (int64_t k = 0; k < n; k++) {  /* the queue never holds a blocked fact */
        int64_t f = queue[k];
        reached[f >> 3] |= (uint8_t)(1u << (f & 7));
    }
}

/* Applicable operators of ``state`` (ascending ids into ``out``; returns their number): operators without a
 * positive precondition (``always``, tested for negative ones), and the operators indexed under each true
 * atom (by_ptr/by_idx), each tested on its positive (pre) and negative (neg) atoms. */
int64_t gsr_applicable(const uint8_t *state, int64_t n_bytes, int64_t n_atoms, const int64_t *always,
                       int64_t n_always, const int64_t *by_ptr, const int64_t *by_idx, const int64_t *opre_ptr,
                       const int64_t *opre_idx, const int64_t *oneg_ptr, const int64_t *oneg_idx, int64_t *out) {
#define HOLDS(A) ((A) >> 3 < n_bytes && (state[(A) >> 3] >> ((A) & 7)) & 1)
    int64_t n = 0;
    for (int64_t j = 0; j < n_always; j++) {
        int64_t i = always[j], ok = 1;
        for (int64_t e = oneg_ptr[i]; e < oneg_ptr[i + 1] && ok; e++) if (HOLDS(oneg_idx[e])) ok = 0;
        if (ok) out[n++] = i;
    }
    for (int64_t byte = 0; byte < n_bytes; byte++) {
        uint8_t b = state[byte];
        while (b) {
            int bit = __builtin_ctz(b);
            b &= (uint8_t)(b - 1);
            int64_t a = byte * 8 + bit;
            if (a >= n_atoms) continue;
            for (int64_t k = by_ptr[a]; k < by_ptr[a + 1]; k++) {
                int64_t i = by_idx[k], ok = 1;
                for (int64_t e = opre_ptr[i]; e < opre_ptr[i + 1] && ok; e++) if (!HOLDS(opre_idx[e])) ok = 0;
                for (int64_t e = oneg_ptr[i]; e < oneg_ptr[i + 1] && ok; e++) if (HOLDS(oneg_idx[e])) ok = 0;
                if (ok) out[n++] = i;
            }
        }
    }
#undef HOLDS
    sort_i64(out, n); /* ascending (the buckets interleave) */
    return n;
}
