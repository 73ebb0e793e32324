/*
 * frappecount: a QEMU 7.2 TCG plugin (plugin API v1, Debian 12's qemu-user)
 * that counts the guest instructions of an ARM program (A32 under qemu-arm,
 * A64 under qemu-aarch64) per function of the main executable and per
 * interval between marker calls. Used by scripts/arm-count.sh; based on the
 * team's armcount plugin (same A32 instruction classes; A64 instructions are
 * sorted into the same twelve slots, named in the log's first line).
 *
 * Attribution:
 *  - an instruction inside a symbol of the main executable (unstripped,
 *    non-PIE so that addresses match `nm`) counts to that function ("self");
 *  - an instruction without a symbol (shared libraries: libc, libm,
 *    libstdc++, OpenCV; PLT stubs) or in a symbol starting with "__" (the
 *    libgcc helpers linked into the executable: __aeabi_idiv, __divsi3 ...:
 *    ARMv6 has no divide instruction) counts to the main-executable function
 *    whose BL/BLX (A64: BL/BLR) executed last ("lib", i.e. the library
 *    code it called).
 * Markers: a call to a function whose name starts with `armcount_mark_`
 * (extern "C", noinline) writes one snapshot to the out file. A marker
 * fires at its entry address only: with marks=FILE ("<hex address> <name>"
 * lines, from `nm`) exactly there, without it at the lowest address seen in
 * the function. Anywhere else would be wrong: QEMU ends a translation block
 * at a page boundary, so a marker that straddles a 4 KiB page is also met at
 * the start of a second block in its middle (issue 15: fired twice a call).
 * The log:
 *    A <class names, 12>                      (first line)
 *    M <label> <total insns so far>
 *    C <12 class deltas> <memory-access delta>
 *    B <bucket> <self delta> <lib delta>      (only buckets that changed)
 * where the deltas are counts since the previous marker and <label> is the
 * function name after the prefix. At exit:
 *    N <bucket> <entry address hex> <mangled name>
 * Counters are inline and not atomic: exact for single-threaded guests.
 * vcpus=1 also counts each guest thread (a vCPU under qemu-user) apart, by
 * a callback per translation block into that thread's own slot: exact with
 * threads, at some speed; after each M line (and at exit) one line per
 * thread seen so far, its count since the start:
 *    V <vcpu index> <insns>
 *
 * Compiled against QEMU's qemu-plugin.h and loaded into QEMU:
 * SPDX-License-Identifier: GPL-2.0-or-later
 *
 * Use: qemu-arm -cpu arm1176 -L SYSROOT -d plugin \
 *          -plugin ./libfrappecount.so,out=FILE[,marks=FILE][,vcpus=1] ./prog args
 *      qemu-aarch64 -cpu cortex-a53 -L / -d plugin -plugin ... ./prog args
 */
#include <inttypes.h>
#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <qemu-plugin.h>

QEMU_PLUGIN_EXPORT int qemu_plugin_version = QEMU_PLUGIN_VERSION;

enum cls {
    C_ALU, C_MUL, C_MEDIA, C_BRANCH, C_LOAD, C_STORE, C_LDM, C_STM,
    C_VFP, C_VFP_LDST, C_THUMB, C_OTHER, C_N
};
static const char *const cls_name[C_N] = {
    "alu", "mul", "media_simd32", "branch", "load", "store", "ldm", "stm",
    "vfp", "vfp_ldst", "thumb16", "other"
};
/* A64 in the same slots: no SIMD32 or Thumb; LDP/STP take the LDM/STM
 * slots, NEON and FP data processing the VFP slot. */
static const char *const cls_name_a64[C_N] = {
    "alu", "mul", "-", "branch", "load", "store", "ldp", "stp",
    "simd_fp", "simd_fp_ldst", "-", "other"
};

#define MAX_BUCKETS 65536
#define HASH_SIZE (1 << 17)
#define MARK_PREFIX "armcount_mark_"

typedef struct {
    const char *name;      /* NULL for bucket 0: code before any BL attribution */
    uint64_t entry;        /* lowest address seen */
    uint64_t self, lib;    /* counters (self: inline) */
    uint64_t snap_self, snap_lib;
} Bucket;

static Bucket buckets[MAX_BUCKETS];
static uint32_t n_buckets = 1;
static uint32_t hash_tab[HASH_SIZE]; /* bucket index, 0 = empty */
static uint64_t cls_count[C_N], cls_snap[C_N];
static uint64_t mem_acc, mem_snap;
static uint32_t cur_caller;          /* bucket of the last executed BL/BLX */
static FILE *out;
static bool a64;                     /* qemu-aarch64 */

/* vcpus=1: instructions per guest thread, each slot written by its own
 * vCPU's thread only */
#define MAX_VCPUS 64
static bool per_vcpu;
static struct {
	uint64_t insns;
	char pad[56]; /* one cache line each */
} vcpu_insns[MAX_VCPUS];
static unsigned int vcpus_seen;

/* marks=FILE: the markers' entry addresses from the symbol table */
#define MAX_MARKS 64
static struct {
    uint64_t addr;
    char *label;
    uint64_t fired;
} marks[MAX_MARKS];
static int n_marks = -1;             /* -1: no marks file, use the lowest address seen */

static enum cls classify_a32(uint32_t i)
{
    uint32_t cond = i >> 28, op = (i >> 25) & 7, cp = (i >> 8) & 0xf;
    bool load = (i >> 20) & 1;

    if (cond == 0xf) {
        return C_OTHER;            /* unconditional space: PLD, BLX imm, ... */
    }
    switch (op) {
    case 0:
        if ((i & 0x0ffffff0u) == 0x012fff10u || (i & 0x0ffffff0u) == 0x012fff30u) {
            return C_BRANCH;       /* BX / BLX register */
        }
        if ((i & 0x0f0000f0u) == 0x00000090u) {
            return C_MUL;          /* MUL, MLA, UMULL, SMLAL, ... */
        }
        if ((i & 0x0f900090u) == 0x01000080u) {
            return C_MUL;          /* SMLAxy, SMULxy, SMULWy, ... */
        }
        if ((i & 0x90u) == 0x90u && (i & 0x60u) != 0) {
            if (!load && (i & 0x60u) == 0x40u) {
                return C_LOAD;     /* LDRD */
            }
            return load ? C_LOAD : C_STORE;
        }
        return C_ALU;
    case 1:
        return C_ALU;
    case 2:
        return load ? C_LOAD : C_STORE;
    case 3:
        if (i & 0x10u) {
            if ((i & 0x0f800010u) == 0x07000010u) {
                return C_MUL;      /* SMLAD, SMUAD, SMLSD, SMMUL, ... */
            }
            return C_MEDIA;        /* ARMv6 SIMD32: UADD8, USAT, SXTB, SEL, USAD8 ... */
        }
        return load ? C_LOAD : C_STORE;
    case 4:
        return load ? C_LDM : C_STM;
    case 5:
        return C_BRANCH;
    case 6:
        return (cp == 10 || cp == 11) ? C_VFP_LDST : C_OTHER;
    default:
        if (i & (1u << 24)) {
            return C_OTHER;        /* SVC */
        }
        return (cp == 10 || cp == 11) ? C_VFP : C_OTHER;
    }
}

static enum cls classify_a64(uint32_t i)
{
    uint32_t op0 = (i >> 25) & 0xf;

    if ((op0 & 0xe) == 0x8) {
        return C_ALU;              /* data processing, immediate */
    }
    if ((op0 & 0xe) == 0xa) {
        if ((i >> 24) == 0xd4 || (i >> 22) == 0x354) {
            return C_OTHER;        /* exceptions (SVC), system (barriers, hints) */
        }
        return C_BRANCH;
    }
    if ((op0 & 0x5) == 0x4) {      /* loads and stores */
        bool simd = (i >> 26) & 1, load = (i >> 22) & 1;
        if (((i >> 28) & 3) == 3 && !simd) {
            load = ((i >> 22) & 3) != 0; /* single register: opc 1x are loads too */
        } else if (((i >> 28) & 3) == 1 && ((i >> 24) & 1) == 0) {
            load = true;           /* literal */
        }
        if (simd) {
            return C_VFP_LDST;
        }
        if (((i >> 27) & 7) == 5) {
            return load ? C_LDM : C_STM; /* pairs */
        }
        return load ? C_LOAD : C_STORE;
    }
    if ((op0 & 0x7) == 0x5) {      /* data processing, register */
        return ((i >> 24) & 0x1f) == 0x1b ? C_MUL : C_ALU;
    }
    if ((op0 & 0x7) == 0x7) {
        return C_VFP;              /* NEON and scalar FP */
    }
    return C_OTHER;
}

static bool is_call_a64(uint32_t i)
{
    return (i & 0xfc000000u) == 0x94000000u ||        /* BL */
           (i & 0xfffffc1fu) == 0xd63f0000u;          /* BLR */
}

static bool is_call_a32(uint32_t i)
{
    if ((i >> 28) == 0xf) {
        return ((i >> 25) & 7) == 5;                    /* BLX imm */
    }
    if (((i >> 24) & 0xf) == 0xb) {
        return true;                                    /* BL */
    }
    return (i & 0x0ffffff0u) == 0x012fff30u;           /* BLX reg */
}

static uint32_t bucket_of(const char *name, uint64_t vaddr)
{
    uint32_t h = (uint32_t)(((uintptr_t)name * 0x9E3779B97F4A7C15ull) >> 40) & (HASH_SIZE - 1);
    while (hash_tab[h]) {
        Bucket *b = &buckets[hash_tab[h]];
        if (b->name == name || strcmp(b->name, name) == 0) {
            if (vaddr < b->entry) {
                b->entry = vaddr;
            }
            return hash_tab[h];
        }
        h = (h + 1) & (HASH_SIZE - 1);
    }
    if (n_buckets >= MAX_BUCKETS) {
        return 0;
    }
    uint32_t k = n_buckets++;
    buckets[k].name = name;
    buckets[k].entry = vaddr;
    hash_tab[h] = k;
    return k;
}

static void on_call(unsigned int vcpu, void *ud)
{
    cur_caller = (uint32_t)(uintptr_t)ud;
}

static void on_lib_tb(unsigned int vcpu, void *ud)
{
    buckets[cur_caller].lib += (uint64_t)(uintptr_t)ud;
}

static void on_tb_vcpu(unsigned int vcpu, void *ud)
{
	/* qemu-user numbers threads as they start; one that ends leaves its slot */
	if (vcpu < MAX_VCPUS) {
		vcpu_insns[vcpu].insns += (uint64_t)(uintptr_t)ud;
		if (vcpu >= vcpus_seen) {
			vcpus_seen = vcpu + 1; /* racy but only grows; read at exit */
		}
	}
}

static void write_mark(const char *label)
{
    uint64_t total = 0;
    for (int c = 0; c < C_N; c++) {
        total += cls_count[c];
    }
    fprintf(out, "M %s %" PRIu64 "\nC", label, total);
    for (int c = 0; c < C_N; c++) {
        fprintf(out, " %" PRIu64, cls_count[c] - cls_snap[c]);
        cls_snap[c] = cls_count[c];
    }
    fprintf(out, " %" PRIu64 "\n", mem_acc - mem_snap);
    mem_snap = mem_acc;
    for (unsigned int v = 0; per_vcpu && v < vcpus_seen; v++) {
	    fprintf(out, "V %u %" PRIu64 "\n", v, vcpu_insns[v].insns);
    }
    for (uint32_t k = 0; k < n_buckets; k++) {
        Bucket *b = &buckets[k];
        if (b->self != b->snap_self || b->lib != b->snap_lib) {
            fprintf(out, "B %u %" PRIu64 " %" PRIu64 "\n", k, b->self - b->snap_self,
                    b->lib - b->snap_lib);
            b->snap_self = b->self;
            b->snap_lib = b->lib;
        }
    }
}

static void on_mark(unsigned int vcpu, void *ud)
{
    if (out) {
        write_mark((const char *)ud);
    }
}

static void on_mark_exact(unsigned int vcpu, void *ud)
{
    int k = (int)(uintptr_t)ud;
    marks[k].fired++;
    if (out) {
        write_mark(marks[k].label);
    }
}

/* the marks=FILE entry at this address, or -1 */
static int mark_at(uint64_t va)
{
    for (int k = 0; k < n_marks; k++) {
        if (marks[k].addr == va) {
            return k;
        }
    }
    return -1;
}

static int read_marks(const char *path)
{
    FILE *f = fopen(path, "r");
    char name[256];
    unsigned long long addr;
    if (!f) {
        fprintf(stderr, "frappecount: cannot read %s\n", path);
        return -1;
    }
    n_marks = 0;
    while (fscanf(f, "%llx %255s", &addr, name) == 2) {
        if (strncmp(name, MARK_PREFIX, strlen(MARK_PREFIX)) != 0) {
            continue;
        }
        if (n_marks == MAX_MARKS) {
            fprintf(stderr, "frappecount: more than %d markers in %s\n", MAX_MARKS, path);
            break;
        }
        marks[n_marks].addr = addr;
        marks[n_marks].label = strdup(name + strlen(MARK_PREFIX));
        n_marks++;
    }
    fclose(f);
    return 0;
}

static void tb_trans(qemu_plugin_id_t id, struct qemu_plugin_tb *tb)
{
    size_t n = qemu_plugin_tb_n_insns(tb);
    size_t lib_insns = 0;
    for (size_t k = 0; k < n; k++) {
        struct qemu_plugin_insn *insn = qemu_plugin_tb_get_insn(tb, k);
        const char *s = qemu_plugin_insn_symbol(insn);
        uint64_t va = qemu_plugin_insn_vaddr(insn);
        uint32_t w = 0;
        enum cls c = C_THUMB;
        bool call = false;
        if (qemu_plugin_insn_size(insn) == 4) {
            memcpy(&w, qemu_plugin_insn_data(insn), 4);
            c = a64 ? classify_a64(w) : classify_a32(w);
            call = a64 ? is_call_a64(w) : is_call_a32(w);
        }
        qemu_plugin_register_vcpu_insn_exec_inline(insn, QEMU_PLUGIN_INLINE_ADD_U64,
                                                   &cls_count[c], 1);
        qemu_plugin_register_vcpu_mem_inline(insn, QEMU_PLUGIN_MEM_RW,
                                             QEMU_PLUGIN_INLINE_ADD_U64, &mem_acc, 1);
        /* no symbol (shared libraries, PLT) or a libgcc helper (__aeabi_idiv,
         * __udivsi3, ...): counted to the caller */
        if (!s || !*s || (s[0] == '_' && s[1] == '_')) {
            lib_insns++;
            continue;
        }
        uint32_t b = bucket_of(s, va);
        qemu_plugin_register_vcpu_insn_exec_inline(insn, QEMU_PLUGIN_INLINE_ADD_U64,
                                                   &buckets[b].self, 1);
        if (call) {
            qemu_plugin_register_vcpu_insn_exec_cb(insn, on_call, QEMU_PLUGIN_CB_NO_REGS,
                                                   (void *)(uintptr_t)b);
        }
        /* Only at the marker's entry (see the top). Without marks=FILE the
         * entry is the lowest address seen: a marker is entered by a call,
         * so its first TB starts at its entry. */
        if (n_marks >= 0) {
            int m = mark_at(va);
            if (m >= 0) {
                qemu_plugin_register_vcpu_insn_exec_cb(insn, on_mark_exact, QEMU_PLUGIN_CB_NO_REGS,
                                                       (void *)(uintptr_t)m);
            }
        } else if (strncmp(s, MARK_PREFIX, strlen(MARK_PREFIX)) == 0 && va == buckets[b].entry) {
            qemu_plugin_register_vcpu_insn_exec_cb(insn, on_mark, QEMU_PLUGIN_CB_NO_REGS,
                                                   (void *)(s + strlen(MARK_PREFIX)));
        }
    }
    if (per_vcpu) {
	    qemu_plugin_register_vcpu_tb_exec_cb(tb, on_tb_vcpu, QEMU_PLUGIN_CB_NO_REGS, (void *)(uintptr_t)n);
    }
    if (lib_insns) {
        qemu_plugin_register_vcpu_tb_exec_cb(tb, on_lib_tb, QEMU_PLUGIN_CB_NO_REGS,
                                             (void *)(uintptr_t)lib_insns);
    }
}

static void at_exit(qemu_plugin_id_t id, void *p)
{
    uint64_t total = 0;
    char line[160];
    for (int c = 0; c < C_N; c++) {
        total += cls_count[c];
    }
    snprintf(line, sizeof line, "frappecount: insns %" PRIu64 ", functions %u\n", total, n_buckets - 1);
    qemu_plugin_outs(line);
    /* a marker that never fired: its address in marks=FILE is not where
     * the program runs it (a PIE, or a file of another build) */
    for (int k = 0; k < n_marks; k++) {
        if (!marks[k].fired) {
            snprintf(line, sizeof line, "frappecount: marker %s at 0x%" PRIx64 " never fired\n",
                     marks[k].label, marks[k].addr);
            qemu_plugin_outs(line);
        }
    }
    if (out) {
        write_mark("exit");
        for (uint32_t k = 1; k < n_buckets; k++) {
            fprintf(out, "N %u %" PRIx64 " %s\n", k, buckets[k].entry, buckets[k].name);
        }
        fclose(out);
        out = NULL;
    }
}

QEMU_PLUGIN_EXPORT int qemu_plugin_install(qemu_plugin_id_t id, const qemu_info_t *info,
                                           int argc, char **argv)
{
    for (int k = 0; k < argc; k++) {
        if (strncmp(argv[k], "out=", 4) == 0) {
            out = fopen(argv[k] + 4, "w");
            if (!out) {
                fprintf(stderr, "frappecount: cannot write %s\n", argv[k] + 4);
                return -1;
            }
	} else if (strcmp(argv[k], "vcpus=1") == 0) {
		per_vcpu = true;
	} else if (strncmp(argv[k], "marks=", 6) == 0) {
		if (read_marks(argv[k] + 6) != 0) {
			return -1;
		}
	} else {
		fprintf(stderr, "frappecount: unknown argument %s\n", argv[k]);
		return -1;
	}
    }
    a64 = strcmp(info->target_name, "aarch64") == 0;
    if (!a64 && strcmp(info->target_name, "arm") != 0) {
        fprintf(stderr, "frappecount: classes assume ARM; target is %s\n", info->target_name);
    }
    if (out) {
        fprintf(out, "A");
        for (int c = 0; c < C_N; c++) {
            fprintf(out, " %s", a64 ? cls_name_a64[c] : cls_name[c]);
        }
        fprintf(out, "\n");
    }
    qemu_plugin_register_vcpu_tb_trans_cb(id, tb_trans);
    qemu_plugin_register_atexit_cb(id, at_exit, NULL);
    return 0;
}
