/* The floor's factorization by CHOLMOD (SuiteSparse, from Debian), on the matrices that
 * `cargo run --release --example floor_matrices -- LEVEL DIR` writes: an anchor for the
 * floor of `study speed` (issue 51), not a dependency of the project.
 *
 *   apt-get install libsuitesparse-dev libopenblas0-pthread
 *   cc -O2 -o /tmp/cholmod_floor bench/cholmod_floor.c -I/usr/include/suitesparse -lcholmod -lm
 *   OPENBLAS_NUM_THREADS=1 /tmp/cholmod_floor DIR/block_0.bin DIR/block_1.bin
 *
 * Per block and per factorization kind (CHOLMOD's automatic choice, then supernodal
 * forced; simplicial was 2.2x slower than supernodal at level 5 and is left out), the best
 * of 3 of: cholmod_analyze (CHOLMOD's default
 * orderings: AMD, and METIS where the library has it, the better fill kept),
 * cholmod_factorize and one cholmod_solve; and the factor's entries. */
#include <cholmod.h>
#include <stdio.h>
#include <stdint.h>
#include <stdlib.h>
#include <time.h>

static double now(void) {
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return t.tv_sec + 1e-9 * t.tv_nsec;
}

static int read_u64(FILE *f, uint64_t *v, size_t n) { return fread(v, 8, n, f) == n; }

int main(int argc, char **argv) {
    if (argc < 2) {
        fprintf(stderr, "usage: cholmod_floor BLOCK.bin...\n");
        return 2;
    }
    cholmod_common c;
    cholmod_start(&c);
    for (int a = 1; a < argc; a++) {
        FILE *f = fopen(argv[a], "rb");
        if (!f) { fprintf(stderr, "%s: cannot open\n", argv[a]); return 1; }
        uint64_t head[2];
        if (!read_u64(f, head, 2)) { fprintf(stderr, "%s: short file\n", argv[a]); return 1; }
        size_t n = head[0], nnz = head[1];
        cholmod_sparse *A = cholmod_allocate_sparse(n, n, nnz, 1, 1, -1, CHOLMOD_REAL, &c);
        uint64_t *buf = malloc(8 * (n + 1 > nnz ? n + 1 : nnz));
        int *p = A->p, *i = A->i;
        if (!read_u64(f, buf, n + 1)) return 1;
        for (size_t k = 0; k <= n; k++) p[k] = (int)buf[k];
        if (!read_u64(f, buf, nnz)) return 1;
        for (size_t k = 0; k < nnz; k++) i[k] = (int)buf[k];
        if (fread(A->x, 8, nnz, f) != nnz) return 1;
        fclose(f);
        free(buf);
        cholmod_dense *b = cholmod_ones(n, 1, CHOLMOD_REAL, &c);
        const char *kinds[2] = {"auto", "supernodal"};
        int modes[2] = {CHOLMOD_AUTO, CHOLMOD_SUPERNODAL};
        for (int m = 0; m < 2; m++) {
        c.supernodal = modes[m];
        double best[3] = {1e300, 1e300, 1e300};
        double fill = 0;
        for (int r = 0; r < 3; r++) {
            double t0 = now();
            cholmod_factor *L = cholmod_analyze(A, &c);
            double t1 = now();
            cholmod_factorize(A, L, &c);
            double t2 = now();
            cholmod_dense *x = cholmod_solve(CHOLMOD_A, L, b, &c);
            double t3 = now();
            if (c.status != CHOLMOD_OK) { fprintf(stderr, "%s: CHOLMOD status %d\n", argv[a], c.status); return 1; }
            fill = c.lnz;
            if (t3 - t0 < best[0] + best[1] + best[2]) {
                best[0] = t1 - t0; best[1] = t2 - t1; best[2] = t3 - t2;
            }
            cholmod_free_dense(&x, &c);
            cholmod_free_factor(&L, &c);
        }
        printf("%s: n %zu nnz(lower) %zu factor entries %.0f (%s ordering); cholmod %s: analyse %.4f s, factor %.4f s, solve %.4f s, total %.4f s\n",
               argv[a], n, nnz, fill, c.selected >= 0 && c.method[c.selected].ordering == CHOLMOD_METIS ? "METIS" : "AMD or other",
               kinds[m], best[0], best[1], best[2], best[0] + best[1] + best[2]);
        }
        cholmod_free_dense(&b, &c);
        cholmod_free_sparse(&A, &c);
    }
    cholmod_finish(&c);
    return 0;
}
