import gzip
T0=1000
HB="ITEM: BOX BOUNDS ff ff ff\n-0.1 0.1\n-0.1 0.1\n-0.1 0.1\n"
def atom_frame(step, ids):
    s=f"ITEM: TIMESTEP\n{step}\nITEM: NUMBER OF ATOMS\n{len(ids)}\n{HB}ITEM: ATOMS id type x y z vx vy vz radius f_Temp \n"
    for i in ids:
        sh=(step-T0)*1e-5
        t=(30.0 if i<=5 else 10.0)+(step-T0)*1e-3
        s+=f"{i} 1 {0.001*i+sh} {-0.002*i} {0.003*(i%7)} 0.5 -0.25 {i*1e-3} 0.005 {t} \n"
    return s
ids=list(range(1,11))
atoms="".join(atom_frame(s, ids if s!=T0+30 else ids[::-1]) for s in [T0,T0+15,T0+30,T0+60])
open("atoms.dump","w").write(atoms)
gzip.open("atoms.dump.gz","wt").write(atoms[:len(atoms)//2+0] if False else atoms)
def contacts_at(step):
    c=[(2,1,4e-6+(step-T0)*1e-8)]
    if step<=T0+20: c.append((3,4,1e-6))
    if step==T0+30: c.append((250,5,2.25e-6))
    return c
def cframe(step, layout):
    c=contacts_at(step)
    cols={"area":4,"pos":9,"delta":10}[layout]
    s=f"ITEM: TIMESTEP\n{step}\nITEM: NUMBER OF ENTRIES\n{len(c)}\n{HB}ITEM: ENTRIES "+" ".join(f"c_pc[{k}]" for k in range(1,cols+1))+" \n"
    for i,j,a in c:
        if layout=="area": s+=f"{i} {j} 0 {a:e} \n"
        else:
            s+=f"{0.001*i} 0 0 {0.001*i+0.0095} 0 0 {i} {j} 0"+(" 0.0005" if layout=="delta" else "")+" \n"
    return s
for lay in ["area","pos","delta"]:
    txt="".join(cframe(T0+10*k, lay) for k in range(5))
    open(f"contacts-{lay}.dump","w").write(txt)
gzip.open("contacts-area.dump.gz","wt").write(open("contacts-area.dump").read())
