/* sim/run/schedmodel.c -- the scheduling pass's machine model from the config (see schedmodel.h).
 *
 * Owns: schedmodel_fill. Must not: read a config key directly (every value comes through a
 * unit's params function and its result-time function, as the timing model gets it).
 */
#include "schedmodel.h"

#include <string.h>

#include "../machine/interconnect.h"
#include "../machine/raybuf.h"
#include "../machine/scenemem.h"
#include "../machine/simd.h"
#include "../machine/spad.h"
#include "../mem/bus.h"

void schedmodel_fill(const CfgMachine *cfg, AsmSchedModel *m)
{
    SimdParams sp;
    RayBufs rb;
    Xbar x;
    Spad s;
    CacheParams l1;
    BusParams bus;
    memset(&rb, 0, sizeof rb);
    memset(&x, 0, sizeof x);
    memset(&s, 0, sizeof s);
    simd_params(cfg, &sp);
    rb_params(cfg, &rb.p);
    xbar_params(cfg, &x.p);
    spad_params(cfg, &s.p);
    mem_l1_params(cfg, &l1);
    bus_params(cfg, &bus);
    memset(m, 0, sizeof *m);
    for (int u = 0; u < ISA_U_COUNT; u++) {
        m->lat[u] = sp.lat[u];
        m->issue[u] = sp.issue[u];
    }
    m->lat[ISA_U_RBUF] = (int)rb_gather_ready(&rb, &x, 0);
    m->idm_load = (int)rb_scalar_ready(&rb, 0);
    m->lat[ISA_U_SPAD] = (int)spad_load_ready(&s, 0);
    m->lat[ISA_U_SCENE] = m->lat[ISA_U_FB] = l1.bytes ? l1.hit_latency : bus.latency;
    m->lanes = cfg->core_simd_width;
}
